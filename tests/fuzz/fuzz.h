// Shared by the fuzz harnesses (libFuzzer): each feeds the fuzzer's bytes to one of the project's readers, as a
// file, the way the commands read them. A reader may refuse its input only with a pdvo::Error (the one-line
// message a command prints); any other exception, like a crash, a hang or undefined behaviour, is a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "pdvo/common/errors.h"

namespace pdvo::fuzz {

// The input files of this process, removed when it ends (a crash leaves the crashing input behind).
struct InputFiles {
  std::set<std::string> paths;
  ~InputFiles() {
    for (const std::string& path : paths) std::remove(path.c_str());
  }
};

// A file of this process's own in the temporary folder, rewritten for every input.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& extension) {
  static InputFiles files;
  const std::string path =
      (std::filesystem::temp_directory_path() / ("pdvo-fuzz-" + std::to_string(getpid()) + extension)).string();
  files.paths.insert(path);
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), size);
  return path;
}

// Runs `read`; returns normally if it succeeds or throws a pdvo::Error, aborts (a finding) otherwise.
template <class Read>
void ExpectOnlyPdvoErrors(const char* reader, Read&& read) {
  try {
    read();
  } catch (const Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s threw something other than a pdvo::Error: %s\n", reader, e.what());
    std::abort();
  }
}

}  // namespace pdvo::fuzz
