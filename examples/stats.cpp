// examples/stats.cpp: the statistics of nsp_render's tables (see stats.hpp).
#include "stats.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace nsp_examples {

double median_of(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Row::mean(int ch) const {
    double m = 0.0;
    for (const RenderStats& r : runs) m += r.mean[std::size_t(ch)];
    return m / double(runs.size());
}

double Row::standard_error(int ch) const {
    double v = 0.0;
    for (const RenderStats& r : runs) v += r.channel_variance[std::size_t(ch)] / double(r.samples);
    return std::sqrt(v) / double(runs.size());
}

std::uint64_t Row::nonzero() const {
    std::uint64_t n = 0;
    for (const RenderStats& r : runs) n += r.nonzero;
    return n;
}

double Metrics::eff_ltuv(const Row& row) {
    std::vector<double> v;
    for (std::size_t i = 0; i < row.effective.size(); ++i) v.push_back(row.runs[i].lookups_per_sample() * row.effective[i]);
    return median_of(std::move(v));
}

double time_variance(const Row& r, const Metrics& m) {
    if (r.effective.empty()) return r.median([&](const RenderStats& s) { return m.time_variance(s); });
    std::vector<double> v;
    for (std::size_t i = 0; i < r.effective.size(); ++i) v.push_back(r.runs[i].cpu_seconds_per_sample() * r.effective[i]);
    return median_of(std::move(v));
}

double Reference::contribution(int spp_row) const {
    double v = 0.0;
    for (const double x : stats.pixel_variance) v += x;
    return double(spp_row) * v / double(stats.pixel_variance.size()) / double(spp);
}

double effective_variance(const RenderStats& run, int spp, const Reference& ref) {
    const auto& a = run.pixel_mean;
    const auto& b = ref.stats.pixel_mean;
    if (a.size() != b.size() || a.empty()) throw std::logic_error("effective_variance: image sizes differ");
    double sq = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) sq += (a[i] - b[i]) * (a[i] - b[i]);
    return double(spp) * sq / double(a.size()) - ref.contribution(spp);
}

double effective_image_variance(const RenderStats& run, int spp, const Reference& ref) {
    const auto& a = run.pixel_mean;
    const auto& b = ref.stats.pixel_mean;
    const std::size_t pixels = a.size() / 3;
    double sq = 0.0;
    for (int c = 0; c < 3; ++c) {
        double d = 0.0;
        for (std::size_t i = 0; i < pixels; ++i) d += a[3 * i + std::size_t(c)] - b[3 * i + std::size_t(c)];
        d /= double(pixels);
        sq += d * d;
    }
    return double(spp) * double(pixels) * sq / 3.0 - ref.contribution(spp);
}

std::pair<double, int> mean_gap(const Row& a, const Row& b) {
    std::pair<double, int> worst{0.0, 0};
    for (int c = 0; c < 3; ++c) {
        const double se = std::hypot(a.standard_error(c), b.standard_error(c));
        const double z = se > 0.0 ? std::abs(a.mean(c) - b.mean(c)) / se : 0.0;
        if (z > worst.first) worst = {z, c};
    }
    return worst;
}

const Row* find_row(const std::vector<Row>& rows, std::string_view name) {
    for (const Row& r : rows)
        if (r.c.name == name) return &r;
    return nullptr;
}

const Row* find_row(const std::vector<Row>& rows, std::string_view key, std::string_view majorant) {
    for (const Row& r : rows)
        if (r.c.key == key && r.c.majorant == majorant) return &r;
    return nullptr;
}

std::vector<std::string> majorants_of(const std::vector<Row>& rows) {
    std::vector<std::string> out;
    for (const Row& r : rows)
        if (std::find(out.begin(), out.end(), r.c.majorant) == out.end()) out.push_back(r.c.majorant);
    return out;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

std::string ratio_text(double a, double b) { return b > 0.0 && std::isfinite(a / b) ? num(a / b) : "n/a"; }

std::string without_absorption(const std::string& key) {
    const auto p = key.rfind("_absorb-");
    return p == std::string::npos ? key : key.substr(0, p);
}

}  // namespace nsp_examples
