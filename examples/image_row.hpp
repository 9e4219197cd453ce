// examples/image_row.hpp: what one render of nsp_room or nsp_volume measured (image_render.hpp
// renders it; agreement.hpp compares rows' means).
#pragma once

#include <cstdint>
#include <string>

#include "png_writer.hpp"

namespace nsp_examples {

/// What one render measured.
struct Row {
    std::string name;
    double seconds = 0.0, cpu_seconds = 0.0, lookups = 0.0, variance = 0.0, mean = 0.0, se = 0.0;
    double steps = 0.0;  ///< majorant DDA steps per sample (grid and tree majorants)
    std::uint64_t failed = 0;  ///< paths with a status other than Ok
    nsp_examples::Image image;
    std::string note;  ///< a line printed under the row's table (e.g. the counts a learned row chose)
};

}  // namespace nsp_examples
