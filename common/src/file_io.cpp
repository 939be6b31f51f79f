#include "pdvo/common/file_io.h"

#include <zlib.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace fs = std::filesystem;
namespace {

// What an interrupted run removes: the staging folders alive now. The mutex also keeps an interrupt out of a
// write and a Commit() in progress.
std::mutex removal_mutex;
std::set<std::string>& RemoveOnInterrupt() {
  static std::set<std::string> paths;
  return paths;
}

void Register(const std::string& path) {
  std::lock_guard<std::mutex> lock(removal_mutex);
  RemoveOnInterrupt().insert(path);
}

void Unregister(const std::string& path) {
  std::lock_guard<std::mutex> lock(removal_mutex);
  RemoveOnInterrupt().erase(path);
}

// `path` with symbolic links in its last component followed (a dangling link gives the path it points to).
fs::path FollowLinks(fs::path path) {
  path = path.lexically_normal();
  if (!path.has_filename() && path.has_parent_path()) path = path.parent_path();  // "out/" is "out"
  std::error_code ec;
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(path, ec)); ++hops) {
    const fs::path target = fs::read_symlink(path, ec);
    if (ec) break;
    path = target.is_absolute() ? target : path.parent_path() / target;
  }
  return path.lexically_normal();
}

// Staging folders `prefix`PID of processes that are gone are removed. `prefix`PID.old is an earlier output that
// such a process's Commit had moved aside (where the file system cannot exchange two paths): it goes back to
// `target` if the process died before its own output took that place, and is removed if not.
void RemoveStale(const fs::path& folder, const std::string& prefix, const fs::path& target) {
  std::error_code ec;
  std::vector<fs::path> entries;
  for (const auto& entry : fs::directory_iterator(folder, ec)) entries.push_back(entry.path());
  for (const fs::path& path : entries) {
    const std::string name = path.filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    std::string digits = name.substr(prefix.size());
    const bool aside = digits.ends_with(".old");
    if (aside) digits.resize(digits.size() - 4);
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == getpid() || kill(pid, 0) == 0 || errno != ESRCH) continue;
    if (aside && !fs::exists(target, ec)) {
      fs::rename(path, target, ec);
    } else {
      fs::remove_all(path, ec);
    }
  }
}

// Exchanges two paths in one step (Linux renameat2); false where the file system cannot.
bool ExchangePaths(const fs::path& a, const fs::path& b) {
  return syscall(SYS_renameat2, AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), 2 /* RENAME_EXCHANGE */) == 0;
}

}  // namespace

void RemoveStagingOnInterrupt() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // every thread started later inherits the mask
  std::thread([signals] {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) return;
    std::lock_guard<std::mutex> lock(removal_mutex);  // held to the end: a Commit() in progress finishes first
    std::error_code ec;
    // The other threads run on meanwhile: a file one of them opens in a staging folder while it is being removed
    // keeps the folder from going (not empty), so it is removed again until it has gone. Once it has, nothing can
    // make it again: the folders inside one are made only under the lock (WriteFileAtomically).
    for (const std::string& path : RemoveOnInterrupt()) {
      for (int attempt = 0; attempt < 100 && fs::exists(path, ec); ++attempt) fs::remove_all(path, ec);
    }
    _exit(128 + signal);
  }).detach();
}

void CheckExists(const std::string& path, const std::string& what) {
  std::error_code ec;
  PDVO_THROW_CHECK(fs::exists(path, ec), IoError, path << ": " << what << " not found");
}

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const fs::path target = FollowLinks(path);
  // Held throughout, so that an interrupt never removes a staging folder while a write (re)creates its folders,
  // and never leaves a temporary file: it waits until the write is done.
  std::lock_guard<std::mutex> lock(removal_mutex);
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
// A truncated PNG or JPEG, or a PNG with a damaged chunk, is caught here, before the decoder, because libpng and
// libjpeg report such files on stderr themselves. A PNG is a chain of chunks, each with a CRC-32 of its type and
// data, up to IEND; a JPEG ends with its end-of-image marker (possibly followed by a little padding).
void CheckImageIntact(const std::string& path, const std::string& bytes) {
  static const std::string kPngSignature = "\x89PNG\r\n\x1a\n";
  if (bytes.compare(0, kPngSignature.size(), kPngSignature) == 0) {
    const auto be32 = [&](size_t at) {
      const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
      return uint32_t{b[0]} << 24 | uint32_t{b[1]} << 16 | uint32_t{b[2]} << 8 | uint32_t{b[3]};
    };
    for (size_t at = kPngSignature.size();;) {
      PDVO_THROW_CHECK(at + 12 <= bytes.size() && be32(at) <= bytes.size() - at - 12, IoError,
                       path << ": cannot decode image (truncated PNG: no IEND chunk)");
      const uint32_t length = be32(at);
      const std::string type = bytes.substr(at + 4, 4);
      const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(bytes.data() + at + 4), length + 4);
      PDVO_THROW_CHECK(crc == be32(at + 8 + length), IoError,
                       path << ": cannot decode image (corrupt PNG: its " << type << " chunk fails its CRC)");
      if (type == "IEND") break;
      at += 12 + length;
    }
  } else if (bytes.size() > 2 && static_cast<uint8_t>(bytes[0]) == 0xFF && static_cast<uint8_t>(bytes[1]) == 0xD8) {
    const std::string tail = bytes.substr(bytes.size() > 64 ? bytes.size() - 64 : 0);
    PDVO_THROW_CHECK(tail.find("\xFF\xD9") != std::string::npos, IoError,
                     path << ": cannot decode image (truncated JPEG: no end-of-image marker)");
  }
}
}  // namespace

cv::Mat ReadImage(const std::string& path, int flags) {
  const std::string bytes = ReadFile(path);
  PDVO_THROW_CHECK(!bytes.empty(), IoError, path << ": image file is empty");
  CheckImageIntact(path, bytes);
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

StagedOutputDir::StagedOutputDir(const std::string& final_dir) {
  const fs::path target = FollowLinks(fs::absolute(final_dir));
  final_dir_ = target.string();
  std::error_code ec;
  if (fs::exists(target, ec)) {
    PDVO_THROW_CHECK(fs::is_directory(target, ec), IoError, final_dir << ": is a file, expected an output folder");
    PDVO_THROW_CHECK(fs::is_empty(target, ec) || fs::exists(target / kOutputMarker, ec), IoError,
                     final_dir << ": is not empty and holds no earlier pdvo output (no " << kOutputMarker
                               << "); choose a new folder, or empty this one");
  }
  const fs::path parent = target.parent_path();
  fs::create_directories(parent, ec);
  PDVO_THROW_CHECK(fs::is_directory(parent, ec), IoError, parent.string() << ": cannot create the folder");
  const std::string prefix = std::string(".").append(target.filename().string()).append(".partial-");
  RemoveStale(parent, prefix, target);
  staging_dir_ = (parent / (prefix + std::to_string(getpid()))).string();
  fs::remove_all(staging_dir_, ec);
  Register(staging_dir_);
  fs::create_directories(staging_dir_, ec);
  PDVO_THROW_CHECK(!ec, IoError, staging_dir_ << ": cannot create a staging folder");
}

StagedOutputDir::~StagedOutputDir() {
  std::error_code ec;
  fs::remove_all(staging_dir_, ec);
  Unregister(staging_dir_);
}

std::string StagedOutputDir::path(const std::string& name) const { return (fs::path(staging_dir_) / name).string(); }

std::string StagedOutputDir::final_path(const std::string& name) const {
  return (fs::path(final_dir_) / name).string();
}

void StagedOutputDir::Commit() {
  WriteFileAtomically(path(kOutputMarker), "pdvo output\n");
  std::error_code ec;
  {
    std::lock_guard<std::mutex> lock(removal_mutex);  // an interrupt waits until the folder is whole
    if (!fs::exists(final_dir_, ec)) {
      fs::rename(staging_dir_, final_dir_, ec);
    } else if (!ExchangePaths(staging_dir_, final_dir_)) {
      // No atomic exchange on this file system: the old folder is moved aside and the new one in. The old one
      // then goes where the staging folder was (to be removed), or back if the new one could not be moved.
      const std::string aside = staging_dir_ + ".old";
      fs::rename(final_dir_, aside, ec);
      if (!ec) {
        fs::rename(staging_dir_, final_dir_, ec);
        std::error_code ignored;
        fs::rename(aside, ec ? final_dir_ : staging_dir_, ignored);
      }
    }
  }
  PDVO_THROW_CHECK(!ec, IoError, final_dir_ << ": cannot move the output into place (" << ec.message() << ")");
  fs::remove_all(staging_dir_, ec);  // what the folder held before
}

}  // namespace pdvo
