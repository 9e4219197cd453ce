// examples/png_writer.hpp: writes linear-RGB float images as 8-bit sRGB PNGs that a person can open
// (single pictures, and labelled contact sheets of many renders at one exposure), next to the
// float EXRs of exr_writer.hpp. Uses stb_image_write and stb_easy_font (Debian's libstb-dev), kept
// in png_writer.cpp so the renderer's translation units never see the stb headers.
#pragma once

#include <string>
#include <vector>

namespace nsp_examples {

/// A linear-RGB float image: width * height pixels, interleaved R, G, B, top row first (the layout
/// write_exr_rgb takes). The functions below throw std::invalid_argument unless width >= 1,
/// height >= 1 and rgb.size() == width * height * 3.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;
};

/// The exposure that maps the given percentile (e.g. 0.99; clamped to [0, 1]) of the luminance
/// (Rec. 709 weights) of all pixels of all images to 1.0, so that one exposure can be shared by
/// pictures that are to be compared. Pixels with a non-finite channel are ignored, as are null
/// pointers. If that percentile is not positive, the largest positive luminance is mapped to 1.0
/// instead; returns 1 when no pixel has a positive finite luminance (e.g. all are 0).
float exposure_for(const std::vector<const Image*>& images, double percentile = 0.99);

/// Writes `image` to `path` as an 8-bit sRGB PNG: each channel is multiplied by `exposure`,
/// clamped to [0, 1] and encoded with the sRGB transfer curve; pixels with a NaN or infinite
/// channel are drawn magenta (255, 0, 255) so they are never hidden. Throws std::invalid_argument
/// if the buffer size does not match or `exposure` is negative or not finite, std::runtime_error
/// naming the path if the file cannot be written.
void write_png(const std::string& path, const Image& image, float exposure);

/// One picture of a contact sheet and the text printed below it. `image` must not be null.
struct Tile {
    std::string label;
    const Image* image;
};

/// Writes a contact sheet PNG of `tiles` to `path`: the tiles in the given order, left to right
/// then top to bottom, `columns` per row (0: about sqrt(n), at most 6; never more than n). Every
/// tile is scaled up by an integer factor (nearest neighbour) until its longer side is at least
/// `min_tile` pixels; tiles of different sizes are allowed (each cell is as large as the largest
/// scaled tile, the tile centred in it). Below each tile a label strip shows `label` in white on
/// dark grey, wrapped at '_' (kept at the end of the line) and at spaces to fit the cell width
/// (a word still too long is broken anywhere), with text twice the size when cells are wider than
/// 300 pixels; characters outside printable ASCII are shown as '?'. All tiles use the one
/// `exposure` (pass exposure_for of all of them, so brightness compares) and the same encoding
/// as write_png, magenta for non-finite pixels included. Throws std::invalid_argument if `tiles`
/// is empty, an image is null or malformed, `columns` is negative or `exposure` is negative or not
/// finite, std::runtime_error naming the path if the file cannot be written.
void write_contact_sheet(const std::string& path, const std::vector<Tile>& tiles, float exposure, int columns = 0,
                         int min_tile = 128);

}  // namespace nsp_examples
