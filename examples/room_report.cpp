// examples/room_report.cpp: nsp_room's tables and contact sheets (see room_report.hpp).
#include "room_report.hpp"

#include <cstdio>
#include <limits>

#include "agreement.hpp"
#include "png_writer.hpp"

namespace nsp_examples {

std::uint64_t print_table(const RoomTable& t, const std::vector<Row>& rows, int threads) {
    const double samples = double(t.res) * t.res * t.spp;
    std::size_t at = 0;
    best_cost(rows, t.reference, {}, &at);
    const double best = at < rows.size() ? rows[at].cpu_seconds / samples * rows[at].variance
                                       : std::numeric_limits<double>::infinity();
    std::printf("\n%s, %dx%d, %d spp, %d threads): %s\n", t.title.c_str(), t.res, t.res, t.spp, threads, t.scene.c_str());
    std::printf("%-38s %8s %11s %11s %11s %11s %10s %9s %6s\n", "estimator", "seconds", "lookups/spl", "var/spl", "LTUV",
                "cpu-s*var", "cpu/best", "mean", "z");
    std::uint64_t failed = 0;
    const Row& ref = rows[t.reference];
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        const double cpu_var = r.cpu_seconds / samples * r.variance;
        std::printf("%-38s %8.2f %11.3g %11.3g %11.3g %11.3g %10.3g %9.4g %6.2f%s\n", r.name.c_str(), r.seconds, r.lookups,
                    r.variance, r.lookups * r.variance, cpu_var, cpu_var / best, r.mean, z_score(r, ref),
                    flagged(rows, i, t.reference) ? " !" : "");
        failed += r.failed;
    }
    std::printf("var/spl: per-pixel sample variance of the channel mean, averaged over pixels (bdpt rows with light "
                "tracing: from 8 batch images, as their splats land in other pixels); cpu-s*var: thread CPU "
                "seconds per sample x var/spl (lower is better; cpu/best against the best row). z: |mean - mean of %s| "
                "in combined standard errors of the image means. Paths with a failed status: %llu\n",
                ref.name.c_str(), static_cast<unsigned long long>(failed));
    print_flag_notes(rows, t.reference);
    if (t.summary) t.summary(rows);
    for (const Row& r : rows)
        if (!r.note.empty()) std::printf("%s\n", r.note.c_str());
    return failed;
}

std::string write_sheet(const std::string& dir, const std::string& sheet, const std::vector<Row>& rows, std::size_t from,
                        std::size_t to) {
    if (from == to) return "";
    std::vector<Tile> tiles;
    std::vector<const Image*> images;
    for (std::size_t i = from; i < to; ++i) {
        tiles.push_back({std::to_string(i - from + 1) + " " + rows[i].name, &rows[i].image});
        images.push_back(&rows[i].image);
    }
    const std::string path = dir + "/" + sheet;
    write_contact_sheet(path, tiles, exposure_for(images));
    return path;
}

}  // namespace nsp_examples
