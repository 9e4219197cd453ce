// examples/tool.hpp: what nsp_render, nsp_room and nsp_volume share at their edges: one exit-code
// convention, one way to report a bad command line (a message that names the flag as the user
// typed it), checks of the files and directories they are given before any render starts, and a
// main() that lets no exception escape.
//
// The exit codes, the same in the three tools:
//   0  success;
//   1  a runtime failure: a path ended with a failed status, a write failed, an unexpected error;
//   2  a usage error: an unknown flag, a bad value, an input file that is missing or not a regular
//      file or that its loader rejects, an output directory that cannot be created or written.
// Every message is one line on stderr, "nsp_<tool>: <what>"; the usage errors of the flags
// themselves add a second line pointing to --help.
#pragma once

#include <charconv>
#include <cmath>
#include <concepts>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace nsp_examples {

/// The exit codes of the example tools (see the file comment).
inline constexpr int kExitOk = 0;
inline constexpr int kExitRuntime = 1;
inline constexpr int kExitUsage = 2;

/// A usage error: run_tool prints "nsp_<tool>: what()" (and with `help_hint` the pointer to
/// --help) and exits kExitUsage.
class UsageError : public std::runtime_error {
public:
    explicit UsageError(const std::string& what, bool help_hint = false)
        : std::runtime_error(what), help_hint_(help_hint) {}
    bool help_hint() const { return help_hint_; }

private:
    bool help_hint_;
};

/// "" if `text` is a number of type T (all of it, decimal; for floating point also finite) in
/// [lo, hi], and then stores it in *out; else what is wrong with it, e.g. "'nan' is not finite",
/// "-1 is out of range [0, 1000]". The flag's name is the caller's to add.
template <class T>
    requires std::integral<T> || std::floating_point<T>
std::string check_number(std::string_view text, T lo, T hi, T* out = nullptr) {
    std::ostringstream range;
    range << text << " is out of range [" << +lo << ", " << +hi << "]";
    const std::string_view digits = text.starts_with('+') ? text.substr(1) : text;  // from_chars takes no '+'
    if constexpr (std::is_unsigned_v<T>)  // "-1": a negative number, not a malformed one
        if (digits.size() > 1 && digits[0] == '-' && digits[1] >= '0' && digits[1] <= '9') return range.str();
    T v{};
    const char* end = digits.data() + digits.size();
    const auto [stop, ec] = std::from_chars(digits.data(), end, v);
    if (digits.empty() || digits[0] == '+' || stop != end || ec == std::errc::invalid_argument)
        return "'" + std::string(text) + (std::is_integral_v<T> ? "' is not an integer" : "' is not a number");
    if (ec == std::errc::result_out_of_range) return range.str();
    if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(v)) return "'" + std::string(text) + "' is not finite";
    if (v < lo || v > hi) return range.str();
    if (out) *out = v;
    return "";
}

/// check_number for a command-line value: the number, or UsageError "<flag>: <what is wrong>".
template <class T>
T parse_number(std::string_view flag, std::string_view text, T lo, T hi) {
    T v{};
    if (const std::string err = check_number(text, lo, hi, &v); !err.empty())
        throw UsageError(std::string(flag) + ": " + err, true);
    return v;
}

/// A CLI11 check that a value is an integer in [lo, hi] (CLI11's own Range lets NaN through and
/// reads "-1" into an unsigned option by wrapping it).
CLI::Validator integer_in(long long lo, long long hi);
/// A CLI11 check that a value is a finite number in [lo, hi], or in (lo, hi] with `open_lo`.
CLI::Validator real_in(double lo, double hi, bool open_lo = false);

/// Parses the command line into `app` (CLI11). Before CLI11 sees them, the arguments are checked
/// against the app's flags so that the messages name what the user typed: "unknown flag '--sp'",
/// "--runs needs a value", "--no-png takes no value"; a value that looks like a negative number
/// is joined to its flag ("--seed -1" -> "--seed=-1", which the flag's check then rejects). A bad
/// value gives "<flag>: <what is wrong>". Throws UsageError (with the help hint) on any of them;
/// prints the help and exits 0 on -h or --help.
void parse_flags(CLI::App& app, int argc, char** argv);

/// Creates directory `dir` if missing and checks that a file can be created in it, before
/// anything is rendered; else throws UsageError "<flag> '<dir>': <what failed>: <the OS's reason>".
void require_writable_directory(std::string_view flag, const std::string& dir);

/// Checks that `path` names an existing regular file (not a directory, device or pipe) before a
/// loader opens it; else throws UsageError naming the path, what it is and `what` it should be
/// ("a volume file").
void require_regular_file(const std::string& path, std::string_view what);

/// Checks that a file can be written at `path` (the target of `flag`): its directory exists and
/// `path` is not a directory; else throws UsageError.
void require_writable_file(std::string_view flag, const std::string& path);

/// Prints a usage error's or a runtime error's line(s) on stderr (run_tool's reporting).
void report_error(const char* tool, const std::exception& e, bool help_hint);

/// Runs body() as a tool's main and returns its exit code: UsageError -> "nsp_<tool>: what" (and
/// the --help hint where it has one), kExitUsage; any other std::exception -> "nsp_<tool>: what",
/// kExitRuntime. `tool` is the program's name, e.g. "nsp_room".
template <class Body>
int run_tool(const char* tool, Body&& body) noexcept {
    try {
        try {
            return body();
        } catch (const UsageError& e) {
            report_error(tool, e, e.help_hint());
            return kExitUsage;
        } catch (const std::exception& e) {
            report_error(tool, e, false);
            return kExitRuntime;
        }
    } catch (...) {  // reporting itself failed (e.g. out of memory): still no terminate()
        return kExitRuntime;
    }
}

}  // namespace nsp_examples
