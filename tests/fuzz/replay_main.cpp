// A harness outside libFuzzer (tests/fuzz/CMakeLists.txt): feeds every file under the given files and folders to
// LLVMFuzzerTestOneInput once, so that the inputs fuzzing found (regressions/) run in the normal suite. A harness
// aborts on a finding; an input that takes over PDVO_REPLAY_SECONDS (1 s; 10 s in a sanitized build) fails too.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    if (!std::filesystem::exists(argv[i])) {
      std::printf("%s: not there (no inputs of this kind yet)\n", argv[i]);
    } else if (std::filesystem::is_directory(argv[i])) {
      for (const auto& e : std::filesystem::recursive_directory_iterator(argv[i])) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    } else {
      files.emplace_back(argv[i]);
    }
  }
  double slowest = 0;
  for (const std::filesystem::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      std::fprintf(stderr, "%s: cannot read\n", file.c_str());
      return 1;
    }
    const auto start = std::chrono::steady_clock::now();
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > PDVO_REPLAY_SECONDS) {
      std::fprintf(stderr, "%s: took %.1f s, over the %d s a reader may take\n", file.c_str(), seconds,
                   PDVO_REPLAY_SECONDS);
      return 1;
    }
    slowest = std::max(slowest, seconds);
  }
  std::printf("%zu inputs read, the slowest in %.1f ms\n", files.size(), slowest * 1e3);
  return files.empty() ? 1 : 0;
}
