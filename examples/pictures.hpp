// examples/pictures.hpp: the PNG files of nsp_render: a contact sheet per table (every row's image
// side by side at one exposure, in the order of the table's rows) and a larger picture of each
// example scene, rendered with one MIS estimator of that scene (catalogue.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "cli.hpp"
#include "plan.hpp"
#include "png_writer.hpp"
#include "render_job.hpp"

namespace nsp_examples {

/// The file name stem of table `t`: its set-up, and its mode unless mono (e.g. A, C1_rgb).
std::string table_stem(const TablePlan& t);

/// Writes OUT/<stem>_sheet.png: `images[i]` is row i's image, labelled "i+1 <row name>". Returns
/// the path written.
std::string write_table_sheet(const TablePlan& t, const std::vector<Image>& images, const Options& o);

/// The render of scene `kind`'s larger picture at --picture-res: the catalogue's set-up, mode,
/// estimator (a combination of that mode) and samples per pixel.
struct PictureJob {
    std::string_view mode;
    std::size_t index = 0;  ///< into CombinationsOf<S> of that mode
    RenderRequest rq;
};
PictureJob picture_job(SceneKind kind, const Options& o);

/// Writes OUT/<scene>.png from the picture's rendered `image`; returns the path written.
std::string write_scene_picture(SceneKind kind, const Options& o, const Image& image);

}  // namespace nsp_examples
