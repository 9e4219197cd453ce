// examples/exr_writer.cpp: the OpenEXR side of the example renderer.
#include "exr_writer.hpp"

#include <cstddef>
#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

namespace nsp_examples {

void write_exr_rgb(const std::string& path, int width, int height, const std::vector<float>& rgb) {
    if (width < 1 || height < 1 || rgb.size() != std::size_t(width) * std::size_t(height) * 3u)
        throw std::invalid_argument("write_exr_rgb: the buffer does not hold width x height RGB pixels");
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const char* names[3] = {"R", "G", "B"};
    for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    const std::size_t xstride = 3 * sizeof(float), ystride = xstride * std::size_t(width);
    // OpenEXR's Slice takes a non-const base pointer even for output.
    char* base = const_cast<char*>(reinterpret_cast<const char*>(rgb.data()));
    for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + std::size_t(c) * sizeof(float), xstride, ystride));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(height);
}

}  // namespace nsp_examples
