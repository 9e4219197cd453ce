// examples/pictures.cpp: contact sheets and scene pictures (see pictures.hpp).
#include "pictures.hpp"

#include <filesystem>
#include <stdexcept>

#include "catalogue.hpp"

namespace nsp_examples {

std::string table_stem(const TablePlan& t) {
    std::string stem = t.scene.name();
    if (t.mode != nsp::Mono::name) stem.append("_").append(t.mode);
    return stem;
}

std::string write_table_sheet(const TablePlan& t, const std::vector<Image>& images, const Options& o) {
    std::vector<Tile> tiles;
    std::vector<const Image*> all;
    for (std::size_t i = 0; i < images.size(); ++i) {
        tiles.push_back({std::to_string(i + 1) + " " + t.rows[i].name, &images[i]});
        all.push_back(&images[i]);
    }
    const std::string path = (std::filesystem::path(o.out) / (table_stem(t) + "_sheet.png")).string();
    write_contact_sheet(path, tiles, exposure_for(all));
    return path;
}

PictureJob picture_job(SceneKind kind, const Options& o) {
    const SceneEntry& e = scene_entry(kind);
    const SetupEntry* setup = nullptr;
    for (const SetupEntry& s : e.setups)
        if (s.name == e.picture_setup) setup = &s;
    const Candidate* row = nullptr;
    const std::vector<Candidate> all = candidates(e.picture_mode, {SelectionRule::Uniform});
    for (const Candidate& c : all)
        if (c.emissive == e.emissive && c.name == e.picture_estimator) row = &c;
    if (!setup || !row)
        throw std::logic_error("the catalogue's picture of scene '" + e.name + "' names no compiled row");
    PictureJob job{e.picture_mode, row->index, {}};
    job.rq.scene = setup->choice;
    job.rq.lights = o.lights;
    job.rq.width = job.rq.height = o.picture_res;
    job.rq.spp = e.picture_spp;
    job.rq.threads = o.threads;
    job.rq.seed = o.seed;
    job.rq.estimator = o.estimator;
    // The picture's estimator ratio-tracks its shadow rays whatever --shadow says (it may be one
    // that needs their path pdfs).
    job.rq.estimator.shadow_estimator = nsp::ShadowEstimator::RatioTracking;
    job.rq.majorant = o.majorant;
    return job;
}

std::string write_scene_picture(SceneKind kind, const Options& o, const Image& image) {
    const std::string path = (std::filesystem::path(o.out) / (scene_entry(kind).name + ".png")).string();
    write_png(path, image, exposure_for({&image}));
    return path;
}

}  // namespace nsp_examples
