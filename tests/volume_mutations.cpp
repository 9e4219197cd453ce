// tests/volume_mutations.cpp: nsp_volume_mutations, a survey of what nsp's loaders do with damaged
// volume files. Single-byte changes of a .vdb or .nvdb file that loads, each loaded in a child
// process of its own (a reader that crashes ends the child, not the survey), counted by outcome
// and by the part of the file the byte lies in. docs/volumes.md has the numbers it measured.
//
// usage: nsp_volume_mutations FILE [options]
//   FILE             a .vdb or .nvdb that loads (nsp_volume --export-cloud / --export-plume write them)
//   --grid NAME      the grid to load (density)
//   --count N        mutations (200): offsets uniform over [--from, --to), each byte XORed with 1..255
//   --from A --to B  the byte range to mutate (the whole file)
//   --seed S         the random sequence (1)
//   --skip-checks    .vdb: load without check_vdb_file, to see what OpenVDB alone does
//   --codec C        .nvdb: first rewrite the file with codec none, zip or blosc, and mutate that
//   --timeout T      seconds a load may take (60)
//   --logs DIR       keep each crash's mutated file and the child's stderr (a sanitizer report) there
// Outcomes: rejected by nsp's layout check (check_vdb_file), rejected with the reader's exception
// (OpenVDB's or NanoVDB's, in nsp's message), rejected by nsp's grid checks (name, type, checksum,
// values), read as the same grid (a byte the reader does not use), read as another grid without
// complaint (changed values that pass every check), crashed (a signal, or a sanitizer's exit), hung.
// Built with the tests when OpenVDB is found (target nsp_volume_mutations); POSIX only.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <tbb/global_control.h>

#include <nsp/io/nanovdb.hpp>
#include <nsp/io/openvdb.hpp>

namespace {

namespace fs = std::filesystem;

enum Outcome : int { kValid = 0, kLayout = 10, kReader = 11, kGridCheck = 12, kEscaped = 13 };

bool is_vdb(const std::string& path) { return fs::path(path).extension() == ".vdb"; }

/// Prints an FNV-1a hash of the grid's NanoVDB buffer: the survey tells the intact grid from another.
void print_hash(const nsp::io::NanoDensityGrid& g) {
    const auto* p = reinterpret_cast<const unsigned char*>(&g.grid());
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint64_t i = 0; i < g.grid().gridSize(); ++i) h = (h ^ p[i]) * 1099511628211ull;
    std::printf("grid %016llx\n", (unsigned long long)h);
}

/// The child: loads `path` and exits with its outcome, printing nsp's message on stdout.
int child(const std::string& path, const std::string& grid, bool skip_checks) {
    // One thread (the survey runs beside other work), and a cap on memory outside ASan (whose
    // shadow memory needs the address space): a size field that asks for terabytes fails to allocate.
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
#if !defined(__SANITIZE_ADDRESS__) && !(defined(__has_feature) && __has_feature(address_sanitizer))
    const rlimit limit{rlim_t(8) << 30, rlim_t(8) << 30};
    setrlimit(RLIMIT_AS, &limit);
#endif
    try {
        if (is_vdb(path)) {
            if (!skip_checks) {
                try {
                    nsp::io::check_vdb_file(path);
                } catch (const nsp::InvalidArgument& e) {
                    std::printf("%s\n", e.what());
                    return kLayout;
                }
            }
            print_hash(*nsp::io::detail_vdb::read_grid(path, grid));
        } else {
            print_hash(*nsp::io::load_nvdb(path, grid));
        }
        return kValid;
    } catch (const nsp::InvalidArgument& e) {
        std::printf("%s\n", e.what());
        const std::string m = e.what();
        // The loaders wrap the reader's own exceptions in these messages; every other is nsp's check.
        for (const char* reader : {"is not an OpenVDB file nsp can read: ", "cannot read the grid list of",
                                   "(truncated or corrupted?): ", "cannot convert ", "is not a NanoVDB file nsp can read: ",
                                   "cannot read grid '"})
            if (m.find(reader) != std::string::npos) return kReader;
        return kGridCheck;
    } catch (const std::exception& e) {
        std::printf("escaped: %s\n", e.what());
        return kEscaped;
    }
}

struct Result {
    std::string outcome;  ///< "nsp layout check", "reader exception", ...
    std::string detail;   ///< the message's first line, or the signal
};

/// Runs the child on `path`; its stdout goes to `out_file`, its stderr to `err_file`.
Result run_child(const std::string& self, const std::string& path, const std::string& grid, bool skip_checks, int timeout,
                 const std::string& out_file, const std::string& err_file) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int out = open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err = open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(err, 2);
        std::vector<const char*> argv{self.c_str(), "--child", path.c_str(), grid.c_str()};
        if (skip_checks) argv.push_back("--skip-checks");
        argv.push_back(nullptr);
        execv(self.c_str(), const_cast<char* const*>(argv.data()));
        _exit(127);
    }
    int status = 0;
    const auto start = std::chrono::steady_clock::now();
    while (waitpid(pid, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() - start > std::chrono::seconds(timeout)) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            return {"hung", "killed after " + std::to_string(timeout) + " s"};
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::ifstream f(out_file);
    std::string line;
    std::getline(f, line);
    if (WIFSIGNALED(status)) return {"crashed", std::string("signal ") + strsignal(WTERMSIG(status))};
    switch (WEXITSTATUS(status)) {
    case kValid: return {"read as a valid grid", line};
    case kLayout: return {"rejected by nsp's layout check", line};
    case kReader: return {"rejected with the reader's exception", line};
    case kGridCheck: return {"rejected by nsp's grid checks", line};
    case kEscaped: return {"escaped exception (a bug)", line};
    default: return {"crashed", "exit " + std::to_string(WEXITSTATUS(status)) + " (a sanitizer's report)"};
    }
}

/// The part of the file byte `at` lies in, for the table.
std::string part_of(const std::string& path, std::uint64_t at, const nsp::io::VdbLayout* layout) {
    if (!layout) {  // .nvdb: a 16-byte segment header, per grid 176 bytes of metadata and its name, then the grids
        return at < 16 ? "segment header" : "grid metadata or data";
    }
    (void)path;
    if (layout->grids.empty() || at < layout->grids.front().descriptor) return "header and file metadata";
    for (const auto& g : layout->grids) {
        if (at < g.descriptor || at >= g.end) continue;
        if (at < g.grid) return "grid descriptor";
        if (at < g.blocks) return "grid metadata, transform, topology";
        return "leaf buffers";
    }
    return "after the last grid";
}

std::vector<char> read_all(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}

int survey(int argc, char** argv) {
    std::string file, grid = "density", codec, logs;
    long count = 200, from = 0, to = -1, timeout = 60;
    unsigned seed = 1;
    bool skip_checks = false;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "nsp_volume_mutations: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--grid") grid = next();
        else if (a == "--count") count = std::stol(next());
        else if (a == "--from") from = std::stol(next());
        else if (a == "--to") to = std::stol(next());
        else if (a == "--seed") seed = unsigned(std::stoul(next()));
        else if (a == "--codec") codec = next();
        else if (a == "--timeout") timeout = std::stol(next());
        else if (a == "--logs") logs = next();
        else if (a == "--skip-checks") skip_checks = true;
        else {
            std::fprintf(stderr, "nsp_volume_mutations: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    file = argv[1];
    const fs::path scratch = fs::temp_directory_path() / ("nsp_volume_mutations." + std::to_string(getpid()));
    fs::create_directories(scratch);
    std::string source = file;
    if (!codec.empty()) {  // the .nvdb rewritten with another codec
        const auto c = codec == "zip" ? nanovdb::io::Codec::ZIP : codec == "blosc" ? nanovdb::io::Codec::BLOSC : nanovdb::io::Codec::NONE;
        source = (scratch / ("source_" + codec + ".nvdb")).string();
        nsp::io::write_nvdb(source, nanovdb::io::readGrids<nanovdb::HostBuffer, std::vector>(file), c);
    }
    const std::vector<char> bytes = read_all(source);
    std::unique_ptr<nsp::io::VdbLayout> layout;
    if (is_vdb(source)) layout = std::make_unique<nsp::io::VdbLayout>(nsp::io::check_vdb_file(source));
    if (to < 0 || to > long(bytes.size())) to = long(bytes.size());
    const std::string self = fs::read_symlink("/proc/self/exe").string();
    const std::string mutated = (scratch / ("mutated" + fs::path(source).extension().string())).string();
    const std::string out = (scratch / "stdout").string(), err = (scratch / "stderr").string();
    const Result intact = run_child(self, source, grid, skip_checks, timeout, out, err);
    if (intact.outcome != "read as a valid grid" || intact.detail.empty()) {
        std::fprintf(stderr, "nsp_volume_mutations: '%s' does not load as it is: %s %s\n", source.c_str(),
                     intact.outcome.c_str(), intact.detail.c_str());
        return 1;
    }
    std::printf("nsp_volume_mutations: %s (%zu bytes%s), grid '%s', %ld single-byte changes in bytes [%ld, %ld), seed %u%s\n",
                file.c_str(), bytes.size(), codec.empty() ? "" : (", rewritten with codec " + codec).c_str(), grid.c_str(), count,
                from, to, seed, skip_checks ? ", without nsp's layout check" : "");
    if (layout)
        for (const auto& g : layout->grids)
            std::printf("  grid '%s': descriptor at byte %llu, data %llu, leaf buffers %llu, end %llu\n", g.name.c_str(),
                        (unsigned long long)g.descriptor, (unsigned long long)g.grid, (unsigned long long)g.blocks,
                        (unsigned long long)g.end);
    std::mt19937_64 rng(seed);
    std::map<std::string, int> totals;
    std::map<std::string, std::map<std::string, int>> by_part;
    std::map<std::string, std::string> example;
    if (!logs.empty()) fs::create_directories(logs);
    for (long i = 0; i < count; ++i) {
        const auto at = std::uint64_t(from) + rng() % std::uint64_t(to - from);
        const auto x = char(1 + rng() % 255);
        std::vector<char> bad = bytes;
        bad[at] = char(bad[at] ^ x);
        {
            std::ofstream f(mutated, std::ios::binary);
            f.write(bad.data(), std::streamsize(bad.size()));
        }
        Result r = run_child(self, mutated, grid, skip_checks, timeout, out, err);
        if (r.outcome == "read as a valid grid") {  // the same grid (the byte was not used), or values changed silently
            r.outcome = r.detail == intact.detail ? "read as the same grid" : "read as another grid, no complaint";
            r.detail.clear();
        }
        const std::string part = part_of(source, at, layout.get());
        ++totals[r.outcome];
        ++by_part[part][r.outcome];
        if (!example.count(r.outcome)) example[r.outcome] = "byte " + std::to_string(at) + ": " + r.detail;
        if (r.outcome == "crashed" || r.outcome == "hung" || r.outcome == "escaped exception (a bug)") {
            std::printf("  %s at byte %llu (%s, xor 0x%02x): %s\n", r.outcome.c_str(), (unsigned long long)at, part.c_str(),
                        unsigned(static_cast<unsigned char>(x)), r.detail.c_str());
            if (!logs.empty()) {
                const std::string stem = logs + "/byte" + std::to_string(at);
                fs::copy_file(mutated, stem + fs::path(source).extension().string(), fs::copy_options::overwrite_existing);
                fs::copy_file(err, stem + ".stderr", fs::copy_options::overwrite_existing);
            }
        }
    }
    std::printf("\n| outcome | count | example |\n|---|---|---|\n");
    for (const auto& [outcome, n] : totals) std::printf("| %s | %d | %s |\n", outcome.c_str(), n, example[outcome].substr(0, 160).c_str());
    std::printf("\n| part of the file | outcomes |\n|---|---|\n");
    for (const auto& [part, outcomes] : by_part) {
        std::string s;
        for (const auto& [outcome, n] : outcomes) s += (s.empty() ? "" : ", ") + outcome + " " + std::to_string(n);
        std::printf("| %s | %s |\n", part.c_str(), s.c_str());
    }
    fs::remove_all(scratch);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc >= 4 && std::strcmp(argv[1], "--child") == 0)
        return child(argv[2], argv[3], argc >= 5 && std::strcmp(argv[4], "--skip-checks") == 0);
    if (argc < 2 || argv[1][0] == '-') {
        std::fprintf(stderr, "usage: nsp_volume_mutations FILE [--grid NAME] [--count N] [--from A] [--to B] [--seed S] "
                             "[--skip-checks] [--codec none|zip|blosc] [--timeout T] [--logs DIR]\n");
        return 2;
    }
    return survey(argc, argv);
}
