// examples/pictures.hpp: the PNG files of nsp_render: a contact sheet per table (every row's image
// side by side at one exposure, in the order of the table's rows) and a larger picture of each
// example scene, rendered with one MIS estimator of that scene (catalogue.hpp).
#pragma once

#include <string>
#include <vector>

#include "cli.hpp"
#include "plan.hpp"
#include "png_writer.hpp"

namespace nsp_examples {

/// The file name stem of table `t`: its set-up, and its mode unless mono (e.g. A, C1_rgb).
std::string table_stem(const TablePlan& t);

/// Writes OUT/<stem>_sheet.png: `images[i]` is row i's image, labelled "i+1 <row name>". Returns
/// the path written.
std::string write_table_sheet(const TablePlan& t, const std::vector<Image>& images, const Options& o);

/// The larger picture of scene `kind`: renders it at --picture-res (the catalogue's set-up, mode,
/// estimator and samples per pixel) and writes OUT/<scene>.png. `label` names the render in the
/// progress line. Returns the path written.
std::string render_scene_picture(SceneKind kind, const Options& o, const std::string& label);

/// The samples of the picture of scene `kind` at --picture-res (for the time estimate).
double picture_samples(SceneKind kind, const Options& o);

}  // namespace nsp_examples
