// examples/progress.cpp: the progress lines and the time-left estimate (see progress.hpp).
#include "progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace nsp_examples {

std::size_t Progress::add(std::string table, std::string kind, double samples) {
    items_.push_back({std::move(table), std::move(kind), std::max(samples, 1.0)});
    return items_.size() - 1;
}

void Progress::done(std::size_t id, const std::string& name, double seconds) {
    items_.at(id).seconds = std::max(seconds, 0.0);
    ++done_;
    std::ostringstream line;  // not "[" + std::to_string(..): GCC 12 warns (-Wrestrict, bug 105329)
    line << "  [" << done_ << '/' << items_.size() << "] " << name << ": ";
    char t[32];
    std::snprintf(t, sizeof t, "%.2f s", seconds);
    line << t;
    if (done_ < items_.size()) line << " (about " << duration_text(seconds_left()) << " left)";
    std::fprintf(stderr, "%s\n", line.str().c_str());
}

std::string Progress::next_label(const std::string& name) const {
    std::ostringstream os;
    os << '[' << done_ + 1 << '/' << items_.size() << "] " << name;
    return os.str();
}

double Progress::seconds_left() const {
    // log(seconds / sample) = a[table] + b[kind], fitted to the renders done by alternating
    // means (each step the least-squares optimum of one factor given the other); b has mean 0
    // over the kinds seen, so an unseen kind is an average one.
    std::map<std::string, double> a, b;
    std::vector<const Item*> done;
    for (const Item& it : items_)
        if (it.seconds >= 0.0) {
            done.push_back(&it);
            a[it.table] = 0.0;
            b[it.kind] = 0.0;
        }
    if (done.empty()) return 0.0;
    auto y = [](const Item& it) { return std::log(std::max(it.seconds, 1e-6) / it.samples); };
    for (int iter = 0; iter < 50; ++iter) {
        std::map<std::string, std::pair<double, int>> sa, sb;
        for (const Item* it : done) {
            auto& s = sa[it->table];
            s.first += y(*it) - b[it->kind];
            ++s.second;
        }
        for (auto& [t, v] : a) v = sa[t].first / sa[t].second;
        for (const Item* it : done) {
            auto& s = sb[it->kind];
            s.first += y(*it) - a[it->table];
            ++s.second;
        }
        double mean_b = 0.0;
        for (auto& [k, v] : b) mean_b += (v = sb[k].first / sb[k].second);
        mean_b /= double(b.size());
        for (auto& [k, v] : b) v -= mean_b;
        for (auto& [t, v] : a) v += mean_b;
    }
    double mean_a = 0.0;
    for (const auto& [t, v] : a) mean_a += v;
    mean_a /= double(a.size());
    double left = 0.0;
    for (const Item& it : items_) {
        if (it.seconds >= 0.0) continue;
        const auto ta = a.find(it.table);
        const auto kb = b.find(it.kind);
        const double log_rate = (ta != a.end() ? ta->second : mean_a) + (kb != b.end() ? kb->second : 0.0);
        left += it.samples * std::exp(log_rate);
    }
    return left;
}

std::string Progress::duration_text(double seconds) {
    const long s = std::lround(std::max(seconds, 0.0));
    std::ostringstream os;
    if (s >= 3600) os << s / 3600 << " h " << (s % 3600) / 60 << " min";
    else if (s >= 60) os << s / 60 << " min " << s % 60 << " s";
    else os << s << " s";
    return os.str();
}

}  // namespace nsp_examples
