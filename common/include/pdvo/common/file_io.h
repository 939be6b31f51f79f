// Small file helpers shared by every tool: atomic writes, reading whole files, reading images with clear
// errors.
#pragma once

#include <opencv2/core/mat.hpp>
#include <string>
#include <utility>
#include <vector>

namespace pdvo {

// Writes `content` to a temporary file beside `path`, then renames it over `path`, so a crash never leaves
// a half-written file. Creates missing parent folders. A symbolic link is written through: the file it points to
// is replaced, the link stays. Throws IoError naming the file.
void WriteFileAtomically(const std::string& path, const std::string& content);

// Reads a whole file; throws IoError naming the file if it is missing or unreadable.
std::string ReadFile(const std::string& path);

// The lines of a text file that hold data: blank lines and lines starting with '#' are skipped. Each comes
// with its 1-based line number, for error messages.
std::vector<std::pair<int, std::string>> ReadDataLines(const std::string& path);

// Reads an image (cv::IMREAD_* flags); throws IoError naming the file if it is missing, empty or cannot be
// decoded (e.g. truncated).
cv::Mat ReadImage(const std::string& path, int flags);

// Encodes an image by the extension of `path` (.png, .jpg, ...) and writes it atomically.
void WriteImage(const std::string& path, const cv::Mat& image);

// Throws IoError naming `path` if it does not exist.
void CheckExists(const std::string& path, const std::string& what = "file");

// An output folder that a run owns whole. Files are written to path(name) in a hidden staging folder beside
// it (.NAME.partial-PID) and Commit() puts the staging folder in the folder's place in one step (an atomic
// exchange where the file system has one), so a run that fails or is interrupted leaves no partial output, and a
// run into an earlier run's folder leaves nothing of the earlier run. A folder that is not empty and was not
// written by pdvo (it has no .pdvo-output marker) is refused before any work, so nothing the user made is lost.
// A symbolic link to a folder is followed: the run replaces the folder it points to. Staging folders left by
// processes that no longer run are removed when another run opens the same folder; with
// RemoveStagingOnInterrupt, an interrupted run removes its own.
class StagedOutputDir {
 public:
  explicit StagedOutputDir(const std::string& final_dir);
  ~StagedOutputDir();  // removes the staging folder (a run that did not commit leaves nothing)
  StagedOutputDir(const StagedOutputDir&) = delete;
  StagedOutputDir& operator=(const StagedOutputDir&) = delete;

  // Where to write the file `name` (may contain subfolders) until Commit().
  std::string path(const std::string& name) const;
  // Where the file `name` will be after Commit().
  std::string final_path(const std::string& name) const;
  void Commit();

 private:
  std::string final_dir_, staging_dir_;
};

// The marker file that says a folder holds a pdvo run's output.
inline constexpr const char* kOutputMarker = ".pdvo-output";

// From now on SIGINT and SIGTERM remove the staging folders of the runs alive at that moment (a file being
// written through WriteFileAtomically is finished first, so no temporary file is left) and end the process with
// 128 + the signal's number (130, 143). Call first in main(), before any thread starts: the signals are taken
// by a thread of their own, so that the cleanup runs as ordinary code, not in a handler.
void RemoveStagingOnInterrupt();

}  // namespace pdvo
