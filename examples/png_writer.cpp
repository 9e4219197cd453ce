// examples/png_writer.cpp: the PNG side of the example renderer (sRGB encoding, contact sheets
// with stb_easy_font labels, and the one stb_image_write implementation of the program).
#include "png_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <stdexcept>

// The stb headers are C written for many compilers; their warnings are not ours (included from
// /usr/include they are system headers anyway, but a vendored copy would not be). STATIC keeps
// the implementation's symbols local to this file, so another translation unit may define its own.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

namespace nsp_examples {
namespace {

struct Rgb8 {
    unsigned char r, g, b;
};

constexpr Rgb8 kMagenta{255, 0, 255};        // non-finite pixels
constexpr Rgb8 kBorder{16, 16, 16};          // gutters between and around cells
constexpr Rgb8 kTileBackground{28, 28, 28};  // the part of a cell a smaller tile leaves free
constexpr Rgb8 kLabelBackground{52, 52, 52};
constexpr Rgb8 kLabelText{255, 255, 255};
constexpr int kGutter = 4;       // pixels between cells and around the sheet
constexpr int kLabelMargin = 4;  // pixels (at text scale 1) left and right of the label text
constexpr int kFontLine = 12;    // stb_easy_font's line height at scale 1

void check_image(const Image& image, const char* who) {
    if (image.width < 1 || image.height < 1 ||
        image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3u)
        throw std::invalid_argument(std::string(who) + ": the buffer does not hold width x height RGB pixels");
}

void check_exposure(float exposure, const char* who) {
    if (!std::isfinite(exposure) || exposure < 0.0f)
        throw std::invalid_argument(std::string(who) + ": the exposure must be finite and non-negative");
}

unsigned char srgb8(float linear) {
    const double c = std::clamp(double(linear), 0.0, 1.0);
    const double v = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

/// One pixel (three floats) times exposure, sRGB-encoded; magenta if any channel is not finite.
Rgb8 encode(const float* p, float exposure) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return kMagenta;
    return {srgb8(p[0] * exposure), srgb8(p[1] * exposure), srgb8(p[2] * exposure)};
}

/// An RGB8 picture being composed, written with stb_image_write.
struct Canvas {
    int width, height;
    std::vector<unsigned char> bytes;

    Canvas(int w, int h, Rgb8 fill) : width(w), height(h), bytes(std::size_t(w) * std::size_t(h) * 3u) {
        for (std::size_t i = 0; i < bytes.size(); i += 3) set(i, fill);
    }
    void set(std::size_t byte_index, Rgb8 c) {
        bytes[byte_index] = c.r;
        bytes[byte_index + 1] = c.g;
        bytes[byte_index + 2] = c.b;
    }
    /// Fills [x0, x1) x [y0, y1), clipped to the canvas.
    void fill(int x0, int y0, int x1, int y1, Rgb8 c) {
        x0 = std::max(x0, 0), y0 = std::max(y0, 0);
        x1 = std::min(x1, width), y1 = std::min(y1, height);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set((std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3u, c);
    }
    /// Encodes the canvas and writes it to `path`. Not stbi_write_png, which ignores a failed
    /// fwrite and fclose (a full disk would leave a truncated file and report success).
    void write(const std::string& path) const {
        struct Sink {
            std::FILE* file;
            int error = 0;  // errno of the first failed write
        };
        Sink sink{std::fopen(path.c_str(), "wb")};
        if (!sink.file) throw std::runtime_error("cannot write the PNG file '" + path + "': " + std::strerror(errno));
        const int encoded = stbi_write_png_to_func(
            [](void* context, void* data, int size) {
                Sink& s = *static_cast<Sink*>(context);
                if (s.error == 0 && std::fwrite(data, 1, std::size_t(size), s.file) != std::size_t(size)) s.error = errno;
            },
            &sink, width, height, 3, bytes.data(), width * 3);
        if (std::fclose(sink.file) != 0 && sink.error == 0) sink.error = errno;
        if (!encoded) throw std::runtime_error("cannot write the PNG file '" + path + "': the encoder failed");
        if (sink.error != 0)
            throw std::runtime_error("cannot write the PNG file '" + path + "': " + std::strerror(sink.error));
    }
};

/// The label with everything stb_easy_font cannot draw (outside ' '..'~') replaced: tabs and line
/// breaks by spaces, the rest by '?'.
std::string printable(const std::string& label) {
    std::string s = label;
    for (char& c : s) {
        if (c == '\n' || c == '\r' || c == '\t') c = ' ';
        else if (c < 32 || c > 126) c = '?';
    }
    return s;
}

/// Width in pixels at scale 1 of one line of printable text.
int text_width(const std::string& line) {
    std::vector<char> buf(line.begin(), line.end());
    buf.push_back('\0');
    return stb_easy_font_width(buf.data());
}

/// Splits printable `text` into lines of at most `max_width` pixels (scale 1): breaks after '_'
/// (which stays on the upper line) and at spaces (which are dropped); a piece still too wide is
/// broken between characters. At least one (possibly empty) line.
std::vector<std::string> wrap(const std::string& text, int max_width) {
    struct Piece {
        std::string text;
        bool after_space;
    };
    std::vector<Piece> pieces;
    bool space = false;
    std::string cur;
    for (char c : text) {
        if (c == ' ') {
            if (!cur.empty()) pieces.push_back({cur, space}), cur.clear();
            space = true;
        } else {
            cur += c;
            if (c == '_') pieces.push_back({cur, space}), cur.clear(), space = false;
        }
    }
    if (!cur.empty()) pieces.push_back({cur, space});

    std::vector<std::string> lines;
    std::string line;
    for (const Piece& p : pieces) {
        const std::string joined = line.empty() ? p.text : line + (p.after_space ? " " : "") + p.text;
        if (text_width(joined) <= max_width) {
            line = joined;
            continue;
        }
        if (text_width(p.text) > max_width) {
            line = joined;  // too wide for any line: fill this one, then break between characters
        } else {
            if (!line.empty()) lines.push_back(line);
            line = p.text;
        }
        while (line.size() > 1 && text_width(line) > max_width) {
            std::size_t n = 1;
            while (n + 1 < line.size() && text_width(line.substr(0, n + 1)) <= max_width) ++n;
            lines.push_back(line.substr(0, n));
            line.erase(0, n);
        }
    }
    if (!line.empty() || lines.empty()) lines.push_back(line);
    return lines;
}

/// Draws one line of printable text with its top-left corner at (x, y), every font pixel a
/// scale x scale block, clipped to [clip_x0, clip_x1).
void draw_text(Canvas& canvas, const std::string& line, int x, int y, int scale, int clip_x0, int clip_x1) {
    if (line.empty()) return;
    std::vector<char> text(line.begin(), line.end());
    text.push_back('\0');
    // stb_easy_font needs ~270 bytes a character on average; no glyph has more than 32 quads.
    std::vector<char> vbuf(line.size() * 32u * 64u + 64u);
    unsigned char white[4] = {255, 255, 255, 255};
    const int quads = stb_easy_font_print(0.0f, 0.0f, text.data(), white, vbuf.data(), int(vbuf.size()));
    for (int q = 0; q < quads; ++q) {
        float vx[4], vy[4];
        for (int v = 0; v < 4; ++v) {
            const char* vertex = vbuf.data() + (std::size_t(q) * 4u + std::size_t(v)) * 16u;
            std::memcpy(&vx[v], vertex, sizeof(float));
            std::memcpy(&vy[v], vertex + 4, sizeof(float));
        }
        const int x0 = x + int(std::lround(*std::min_element(vx, vx + 4) * float(scale)));
        const int x1 = x + int(std::lround(*std::max_element(vx, vx + 4) * float(scale)));
        const int y0 = y + int(std::lround(*std::min_element(vy, vy + 4) * float(scale)));
        const int y1 = y + int(std::lround(*std::max_element(vy, vy + 4) * float(scale)));
        canvas.fill(std::max(x0, clip_x0), y0, std::min(x1, clip_x1), y1, kLabelText);
    }
}

}  // namespace

float exposure_for(const std::vector<const Image*>& images, double percentile) {
    std::vector<double> lum;
    for (const Image* image : images) {
        if (!image) continue;
        check_image(*image, "exposure_for");
        const float* p = image->rgb.data();
        for (std::size_t i = 0; i < image->rgb.size(); i += 3) {
            if (!std::isfinite(p[i]) || !std::isfinite(p[i + 1]) || !std::isfinite(p[i + 2])) continue;
            const double y = 0.2126 * double(p[i]) + 0.7152 * double(p[i + 1]) + 0.0722 * double(p[i + 2]);
            if (std::isfinite(y)) lum.push_back(y);
        }
    }
    if (lum.empty()) return 1.0f;
    const double q = std::isnan(percentile) ? 1.0 : std::clamp(percentile, 0.0, 1.0);
    const auto k = std::size_t(std::floor(q * double(lum.size() - 1)));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    double level = lum[k];
    if (!(level > 0.0)) level = *std::max_element(lum.begin() + std::ptrdiff_t(k), lum.end());
    if (!(level > 0.0)) return 1.0f;
    const float exposure = float(1.0 / level);
    return std::isfinite(exposure) && exposure > 0.0f ? exposure : 1.0f;
}

void write_png(const std::string& path, const Image& image, float exposure) {
    check_image(image, "write_png");
    check_exposure(exposure, "write_png");
    Canvas canvas(image.width, image.height, kBorder);
    for (std::size_t i = 0; i < image.rgb.size(); i += 3) canvas.set(i, encode(image.rgb.data() + i, exposure));
    canvas.write(path);
}

void write_contact_sheet(const std::string& path, const std::vector<Tile>& tiles, float exposure, int columns,
                         int min_tile) {
    if (tiles.empty()) throw std::invalid_argument("write_contact_sheet: no tiles");
    if (columns < 0) throw std::invalid_argument("write_contact_sheet: negative number of columns");
    check_exposure(exposure, "write_contact_sheet");
    for (const Tile& t : tiles) {
        if (!t.image) throw std::invalid_argument("write_contact_sheet: the tile '" + t.label + "' has no image");
        check_image(*t.image, "write_contact_sheet");
    }
    const int n = int(tiles.size());
    if (columns == 0) columns = std::min(6, int(std::ceil(std::sqrt(double(n)))));
    columns = std::min(columns, n);
    const int rows = (n + columns - 1) / columns;

    // Integer upscaling per tile; the cell holds the largest scaled tile.
    std::vector<int> factor(tiles.size());
    int cell_w = 1, cell_h = 1;
    for (std::size_t i = 0; i < tiles.size(); ++i) {
        const int longer = std::max(tiles[i].image->width, tiles[i].image->height);
        factor[i] = std::max(1, (std::max(min_tile, 1) + longer - 1) / longer);
        cell_w = std::max(cell_w, tiles[i].image->width * factor[i]);
        cell_h = std::max(cell_h, tiles[i].image->height * factor[i]);
    }

    // Labels: one strip height for all, from the longest wrapped label.
    const int scale = cell_w > 300 ? 2 : 1;
    const int margin = kLabelMargin * scale;
    const int text_room = std::max(1, (cell_w - 2 * margin) / scale);
    std::vector<std::vector<std::string>> labels;
    std::size_t max_lines = 1;
    for (const Tile& t : tiles) {
        labels.push_back(wrap(printable(t.label), text_room));
        max_lines = std::max(max_lines, labels.back().size());
    }
    const int pad_top = 4 * scale, pad_bottom = 2 * scale;
    const int strip_h = pad_top + int(max_lines) * kFontLine * scale + pad_bottom;

    const int pitch_x = cell_w + kGutter, pitch_y = cell_h + strip_h + kGutter;
    Canvas canvas(kGutter + columns * pitch_x, kGutter + rows * pitch_y, kBorder);
    for (int i = 0; i < n; ++i) {
        const Image& image = *tiles[std::size_t(i)].image;
        const int k = factor[std::size_t(i)];
        const int cx = kGutter + (i % columns) * pitch_x, cy = kGutter + (i / columns) * pitch_y;
        canvas.fill(cx, cy, cx + cell_w, cy + cell_h, kTileBackground);
        const int ox = cx + (cell_w - image.width * k) / 2, oy = cy + (cell_h - image.height * k) / 2;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                const std::size_t src = (std::size_t(y) * std::size_t(image.width) + std::size_t(x)) * 3u;
                const Rgb8 c = encode(image.rgb.data() + src, exposure);
                canvas.fill(ox + x * k, oy + y * k, ox + (x + 1) * k, oy + (y + 1) * k, c);
            }
        const int sy = cy + cell_h;
        canvas.fill(cx, sy, cx + cell_w, sy + strip_h, kLabelBackground);
        const auto& lines = labels[std::size_t(i)];
        for (std::size_t l = 0; l < lines.size(); ++l)
            draw_text(canvas, lines[l], cx + margin, sy + pad_top + int(l) * kFontLine * scale, scale, cx,
                      cx + cell_w);
    }
    canvas.write(path);
}

}  // namespace nsp_examples
