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

cv::Mat ReadImage(const std::string& path, int flags) {
  const std::string bytes = ReadFile(path);
  PDVO_THROW_CHECK(!bytes.empty(), IoError, path << ": image file is empty");
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U,
                                 const_cast<char*>(bytes.data())),
                         flags);
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

}  // namespace pdvo
