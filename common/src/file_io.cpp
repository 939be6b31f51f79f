#include "pdvo/common/file_io.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace fs = std::filesystem;

void CheckExists(const std::string& path, const std::string& what) {
  std::error_code ec;
  PDVO_THROW_CHECK(fs::exists(path, ec), IoError, path << ": " << what << " not found");
}

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  const fs::path tmp = target.string() + ".tmp" + std::to_string(getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    PDVO_THROW_CHECK(out.good(), IoError, path << ": cannot open for writing");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out.good()) {
      fs::remove(tmp, ec);
      PDVO_THROW(IoError, path << ": write failed (disk full?)");
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    PDVO_THROW(IoError, path << ": cannot rename temporary file into place");
  }
}

std::string ReadFile(const std::string& path) {
  CheckExists(path);
  PDVO_THROW_CHECK(!fs::is_directory(path), IoError, path << ": is a folder, expected a file");
  std::ifstream in(path, std::ios::binary);
  PDVO_THROW_CHECK(in.good(), IoError, path << ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::pair<int, std::string>> ReadDataLines(const std::string& path) {
  std::istringstream in(ReadFile(path));
  std::vector<std::pair<int, std::string>> lines;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') lines.emplace_back(number, line);
  }
  return lines;
}

namespace {
// A truncated PNG or JPEG is caught here, before the decoder, because libpng and libjpeg report it on stderr
// themselves. A PNG ends with its IEND chunk, a JPEG with its end-of-image marker (possibly followed by a
// little padding).
void CheckNotTruncated(const std::string& path, const std::string& bytes) {
  static const std::string kPngSignature = "\x89PNG\r\n\x1a\n";
  const std::string tail = bytes.substr(bytes.size() > 64 ? bytes.size() - 64 : 0);
  if (bytes.compare(0, kPngSignature.size(), kPngSignature) == 0) {
    PDVO_THROW_CHECK(tail.find("IEND") != std::string::npos, IoError,
                     path << ": cannot decode image (truncated PNG: no IEND chunk)");
  } else if (bytes.size() > 2 && static_cast<uint8_t>(bytes[0]) == 0xFF && static_cast<uint8_t>(bytes[1]) == 0xD8) {
    PDVO_THROW_CHECK(tail.find("\xFF\xD9") != std::string::npos, IoError,
                     path << ": cannot decode image (truncated JPEG: no end-of-image marker)");
  }
}
}  // namespace

cv::Mat ReadImage(const std::string& path, int flags) {
  const std::string bytes = ReadFile(path);
  PDVO_THROW_CHECK(!bytes.empty(), IoError, path << ": image file is empty");
  CheckNotTruncated(path, bytes);
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())), flags);
  } catch (const cv::Exception&) {
    image.release();
  }
  PDVO_THROW_CHECK(!image.empty(), IoError, path << ": cannot decode image (corrupt or truncated?)");
  return image;
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  const std::string ext = fs::path(path).extension().string();
  bool ok = false;
  try {
    ok = cv::imencode(ext.empty() ? ".png" : ext, image, bytes);
  } catch (const cv::Exception& e) {
    PDVO_THROW(IoError, path << ": cannot encode image (" << e.err << ")");
  }
  PDVO_THROW_CHECK(ok, IoError, path << ": cannot encode image");
  WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

StagedOutputDir::StagedOutputDir(const std::string& final_dir) : final_dir_(final_dir) {
  std::error_code ec;
  created_ = !fs::exists(final_dir);
  fs::create_directories(final_dir, ec);
  PDVO_THROW_CHECK(fs::is_directory(final_dir), IoError, final_dir << ": cannot create the output folder");
  staging_dir_ = (fs::path(final_dir) / (".partial-" + std::to_string(getpid()))).string();
  fs::remove_all(staging_dir_, ec);
  fs::create_directories(staging_dir_, ec);
  PDVO_THROW_CHECK(!ec, IoError, staging_dir_ << ": cannot create a staging folder");
}

StagedOutputDir::~StagedOutputDir() {
  std::error_code ec;
  fs::remove_all(staging_dir_, ec);
  if (!committed_ && created_) fs::remove(final_dir_, ec);  // only if empty: never what the user made
}

std::string StagedOutputDir::path(const std::string& name) const { return (fs::path(staging_dir_) / name).string(); }

std::string StagedOutputDir::final_path(const std::string& name) const {
  return (fs::path(final_dir_) / name).string();
}

void StagedOutputDir::Commit() {
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(staging_dir_)) {
    if (!entry.is_regular_file()) continue;
    const fs::path target = fs::path(final_dir_) / fs::relative(entry.path(), staging_dir_);
    fs::create_directories(target.parent_path(), ec);
    fs::rename(entry.path(), target, ec);
    PDVO_THROW_CHECK(!ec, IoError, target.string() << ": cannot move output into place");
  }
  fs::remove_all(staging_dir_, ec);
  committed_ = true;
}

}  // namespace pdvo
