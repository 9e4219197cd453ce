// examples/exr_writer.hpp: writes a float RGB image as OpenEXR (kept in its own translation unit so
// the renderer's templates compile without OpenEXR's headers).
#pragma once

#include <string>
#include <vector>

namespace nsp_examples {

/// Writes `rgb` (width * height pixels, interleaved R, G, B, top row first) to `path` as a
/// ZIP-compressed 32-bit float EXR. Throws std::exception (from OpenEXR) if the file cannot be written.
void write_exr_rgb(const std::string& path, int width, int height, const std::vector<float>& rgb);

}  // namespace nsp_examples
