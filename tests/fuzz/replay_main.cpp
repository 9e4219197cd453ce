// tests/fuzz/replay_main.cpp: replays the fuzz corpus through LLVMFuzzerTestOneInput without
// libFuzzer, so the normal test build (any compiler) checks every input the fuzzer kept.
// usage: nsp_test_fuzz_corpus [FILE_OR_DIR...]; without arguments, the corpus directory compiled in
// as NSP_FUZZ_CORPUS_DIR. An invariant that fails aborts the process (NSP_FUZZ_CHECK).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace fs = std::filesystem;

int main(int argc, char** argv) {
    std::vector<std::string> roots(argv + 1, argv + argc);
#ifdef NSP_FUZZ_CORPUS_DIR
    if (roots.empty()) roots.emplace_back(NSP_FUZZ_CORPUS_DIR);
#endif
    std::vector<fs::path> files;
    for (const auto& r : roots) {
        if (fs::is_directory(r)) {
            for (const auto& e : fs::directory_iterator(r))
                if (e.is_regular_file()) files.push_back(e.path());
        } else if (fs::is_regular_file(r)) {
            files.emplace_back(r);
        } else {
            std::fprintf(stderr, "nsp_test_fuzz_corpus: %s is neither a file nor a directory\n", r.c_str());
            return 2;
        }
    }
    if (files.empty()) {
        std::fprintf(stderr, "nsp_test_fuzz_corpus: no inputs to replay\n");
        return 2;
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
        std::ifstream is(f, std::ios::binary);
        const std::vector<char> bytes{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
        std::fprintf(stderr, "%s\n", f.filename().c_str());  // names the input if an invariant aborts
        LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    }
    std::printf("nsp_test_fuzz_corpus: %zu inputs replayed, every invariant held\n", files.size());
    return 0;
}
