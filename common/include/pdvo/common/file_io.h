// Small file helpers shared by every tool: atomic writes, reading whole files, reading images with clear
// errors.
#pragma once

#include <opencv2/core/mat.hpp>
#include <string>
#include <utility>
#include <vector>

namespace pdvo {

// Writes `content` to a temporary file beside `path`, then renames it over `path`, so a crash never leaves
// a half-written file. Creates missing parent folders. Throws IoError naming the file.
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

// An output folder filled through a hidden staging folder inside it: files are written to path(name) and
// moved into place only by Commit(), so a run that fails leaves no partial output (and no folder, if the run
// created it). Files already in the folder are kept, except those the run replaces on Commit().
class StagedOutputDir {
 public:
  explicit StagedOutputDir(const std::string& final_dir);
  ~StagedOutputDir();  // removes the staging folder unless committed
  StagedOutputDir(const StagedOutputDir&) = delete;
  StagedOutputDir& operator=(const StagedOutputDir&) = delete;

  // Where to write the file `name` (may contain subfolders) until Commit().
  std::string path(const std::string& name) const;
  // Where the file `name` will be after Commit().
  std::string final_path(const std::string& name) const;
  void Commit();

 private:
  std::string final_dir_, staging_dir_;
  bool created_ = false;  // the folder did not exist before
  bool committed_ = false;
};

}  // namespace pdvo
