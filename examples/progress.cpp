// examples/progress.cpp: the progress lines and the time-left estimate (see progress.hpp).
#include "progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace nsp_examples {

std::size_t Progress::add(double samples) {
    items_.push_back({std::max(samples, 1.0)});
    return items_.size() - 1;
}

void Progress::calibrate(std::size_t id, double samples, double seconds) {
    items_.at(id).pilot_rate = std::max(seconds, 0.0) / std::max(samples, 1.0);
}

void Progress::done(std::size_t id, const std::string& name, double seconds) {
    items_.at(id).seconds = std::max(seconds, 0.0);
    ++done_;
    std::ostringstream line;  // not "[" + std::to_string(..): GCC 12 warns (-Wrestrict, bug 105329)
    char t[32];
    std::snprintf(t, sizeof t, "%.2f s", seconds);
    line << "  [" << done_ << '/' << items_.size() << "] " << name << ": " << t;
    if (done_ < items_.size()) line << " (about " << duration_text(seconds_left()) << " left)";
    std::fprintf(stderr, "%s\n", line.str().c_str());
}

std::string Progress::next_label(const std::string& name) const {
    std::ostringstream os;
    os << '[' << done_ + 1 << '/' << items_.size() << "] " << name;
    return os.str();
}

double Progress::seconds_left() const {
    // The renders done: their seconds against their samples, and against what their pilots predicted.
    double seconds = 0.0, samples = 0.0, piloted = 0.0, predicted = 0.0;
    for (const Item& it : items_)
        if (it.seconds >= 0.0) {
            seconds += it.seconds;
            samples += it.samples;
            if (it.pilot_rate >= 0.0) piloted += it.seconds, predicted += it.samples * it.pilot_rate;
        }
    const double correction = predicted > 0.0 ? piloted / predicted : 1.0;
    double left = 0.0;
    for (const Item& it : items_) {
        if (it.seconds >= 0.0) continue;
        if (it.pilot_rate >= 0.0) left += it.samples * it.pilot_rate * correction;
        else if (samples > 0.0) left += it.samples * seconds / samples;
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
