// examples/tool.cpp: the example tools' command-line parsing, file checks and error reporting
// (see tool.hpp).
#include "tool.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <system_error>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>

namespace nsp_examples {

void report_error(const char* tool, const std::exception& e, bool help_hint) {
    std::cerr << tool << ": " << e.what() << "\n";
    if (help_hint) std::cerr << "(" << tool << " --help lists the flags)\n";
}

CLI::Validator integer_in(long long lo, long long hi) {
    return CLI::Validator(
        [lo, hi](std::string& s) { return check_number<long long>(s, lo, hi); },
        "INT in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

CLI::Validator real_in(double lo, double hi, bool open_lo) {
    std::ostringstream desc;
    desc << "in " << (open_lo ? "(" : "[") << lo << ", " << hi << "]";
    return CLI::Validator(
        [lo, hi, open_lo](std::string& s) {
            double v = 0.0;
            std::string err = check_number<double>(s, lo, hi, &v);
            if (err.empty() && open_lo && v == lo) {
                std::ostringstream os;
                os << s << " is out of range (" << lo << ", " << hi << "]";
                err = os.str();
            }
            return err;
        },
        desc.str());
}

namespace {

/// The app's flags by their names as typed ("--res", "-h"): which take a value, which do not.
struct FlagNames {
    std::vector<std::string> takes_value, no_value;
    bool positionals = false;

    explicit FlagNames(const CLI::App& app) {
        for (const CLI::Option* opt : app.get_options()) {
            if (!opt->nonpositional()) {
                positionals = true;
                continue;
            }
            auto& list = opt->get_expected_max() == 0 ? no_value : takes_value;  // a flag expects no value
            for (const std::string& n : opt->get_lnames()) list.push_back("--" + n);
            for (const std::string& n : opt->get_snames()) list.push_back("-" + n);
        }
    }
    static bool has(const std::vector<std::string>& names, const std::string& n) {
        return std::find(names.begin(), names.end(), n) != names.end();
    }
};

/// The arguments for CLI11 (in its reverse order), checked against the app's flags (tool.hpp).
std::vector<std::string> checked_arguments(const CLI::App& app, int argc, char** argv) {
    const FlagNames names(app);
    std::vector<std::string> args;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a.size() < 2 || a[0] != '-') {  // a positional argument ("-" alone too)
            if (!names.positionals) throw UsageError("unexpected argument '" + a + "'", true);
            args.push_back(a);
            continue;
        }
        const auto eq = a.find('=');
        const std::string name = a.starts_with("--") ? a.substr(0, eq) : a;
        if (FlagNames::has(names.no_value, name)) {
            if (eq != std::string::npos) throw UsageError(name + " takes no value", true);
            args.push_back(a);
        } else if (FlagNames::has(names.takes_value, name)) {
            if (eq == std::string::npos) {
                if (i + 1 >= argc) throw UsageError(name + " needs a value", true);
                a += "=" + std::string(argv[++i]);  // the next argument is its value, whatever it looks like
            }
            args.push_back(a);
        } else {
            throw UsageError("unknown flag '" + a + "'", true);
        }
    }
    std::reverse(args.begin(), args.end());
    return args;
}

/// Creates a file in `dir` and removes it: "" if that worked, else the OS's reason.
std::string probe_write(const std::filesystem::path& dir) {
    const std::filesystem::path probe = dir / (".nsp-write-check-" + std::to_string(::getpid()));
    std::FILE* f = std::fopen(probe.c_str(), "wx");
    if (!f) return std::strerror(errno);
    std::fclose(f);
    std::error_code ec;
    std::filesystem::remove(probe, ec);
    return "";
}

}  // namespace

void parse_flags(CLI::App& app, int argc, char** argv) {
    try {
        std::vector<std::string> args = checked_arguments(app, argc, argv);
        app.parse(args);
    } catch (const CLI::CallForHelp&) {
        std::cout << app.help();
        std::exit(kExitOk);
    } catch (const CLI::ParseError& e) {
        throw UsageError(e.what(), true);
    }
}

void require_writable_directory(std::string_view flag, const std::string& dir) {
    const std::string what = std::string(flag) + " '" + dir + "'";
    if (dir.empty()) throw UsageError(std::string(flag) + " needs a directory name");
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw UsageError(what + ": cannot create the directory: " + ec.message());
    if (!std::filesystem::is_directory(dir, ec)) throw UsageError(what + " is not a directory");
    if (const std::string why = probe_write(dir); !why.empty())
        throw UsageError(what + ": cannot write in the directory: " + why);
}

void require_regular_file(const std::string& path, std::string_view what) {
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(path, ec);
    if (st.type() == std::filesystem::file_type::not_found) throw UsageError("cannot open '" + path + "': no such file");
    if (ec) throw UsageError("cannot open '" + path + "': " + ec.message());
    if (st.type() == std::filesystem::file_type::directory)
        throw UsageError("'" + path + "' is a directory, not " + std::string(what));
    if (st.type() != std::filesystem::file_type::regular)
        throw UsageError("'" + path + "' is not a regular file (a device, pipe or socket), not " + std::string(what));
}

void require_writable_file(std::string_view flag, const std::string& path) {
    const std::string what = std::string(flag) + " '" + path + "'";
    std::error_code ec;
    if (path.empty()) throw UsageError(std::string(flag) + " needs a file name");
    if (std::filesystem::is_directory(path, ec)) throw UsageError(what + " is a directory, not a file");
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (dir.empty()) dir = ".";
    const std::filesystem::file_type type = std::filesystem::status(dir, ec).type();
    if (type == std::filesystem::file_type::not_found)
        throw UsageError(what + ": the directory '" + dir.string() + "' does not exist");
    if (type != std::filesystem::file_type::directory)
        throw UsageError(what + ": '" + dir.string() + "' is not a directory");
    if (const std::string why = probe_write(dir); !why.empty())
        throw UsageError(what + ": cannot write in '" + dir.string() + "': " + why);
}

}  // namespace nsp_examples
