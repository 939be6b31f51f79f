#include "pdvo/common/logging.h"

#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <mutex>

#include "pdvo/common/errors.h"

namespace pdvo {

double ResidentMiB() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1 << 20);
}

void KeepFreedMemory(int mib) {
#if defined(__GLIBC__)
  const int bytes = mib << 20;
  mallopt(M_MMAP_THRESHOLD, std::min(bytes, 32 << 20));  // glibc's largest; above it blocks are mapped
  mallopt(M_TRIM_THRESHOLD, bytes);
#else
  (void)mib;
#endif
}

namespace {
std::atomic<int> g_log_level{static_cast<int>(LogLevel::kInfo)};
std::mutex g_stderr_mutex;

const char* LevelTag(LogLevel level) {
  switch (level) {
    case LogLevel::kError: return "error: ";
    case LogLevel::kWarning: return "warning: ";
    case LogLevel::kInfo: return "";
    case LogLevel::kDebug: return "debug: ";
  }
  return "";
}

std::string FormatSeconds(double s) {
  char buf[32];
  const int total = static_cast<int>(s + 0.5);
  if (total >= 3600) {
    std::snprintf(buf, sizeof(buf), "%dh%02dm", total / 3600, (total / 60) % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%d:%02d", total / 60, total % 60);
  }
  return buf;
}
}  // namespace

void SetLogLevel(LogLevel level) { g_log_level = static_cast<int>(level); }
LogLevel GetLogLevel() { return static_cast<LogLevel>(g_log_level.load()); }

LogLevel ParseLogLevel(const std::string& text) {
  if (text == "error" || text == "0") return LogLevel::kError;
  if (text == "warning" || text == "1") return LogLevel::kWarning;
  if (text == "info" || text == "2") return LogLevel::kInfo;
  if (text == "debug" || text == "3") return LogLevel::kDebug;
  PDVO_THROW(InvalidArgument, "unknown verbosity '" << text << "' (use error, warning, info, debug or 0-3)");
}

detail::LogMessage::~LogMessage() {
  std::lock_guard<std::mutex> lock(g_stderr_mutex);
  std::cerr << LevelTag(level_) << stream_.str() << '\n';
}

Progress::Progress(std::string what, size_t total, double plain_interval_s)
    : what_(std::move(what)),
      total_(total),
      plain_interval_s_(plain_interval_s),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_),
      uncaught_at_start_(std::uncaught_exceptions()) {}

Progress::~Progress() {
  // Unwinding from an error: the loop did not finish, and its error line should stand alone.
  if (std::uncaught_exceptions() > uncaught_at_start_) finished_ = true;
  Finish();
}

double Progress::Rate() const {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return s > 0 ? done_ / s : 0.0;
}

void Progress::Step(size_t n) {
  done_ += n;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_print_).count();
  if (since >= (tty_ ? 0.1 : plain_interval_s_)) {
    last_print_ = now;
    Print(false);
  }
}

void Progress::Finish() {
  if (finished_) return;
  finished_ = true;
  Print(true);
}

void Progress::Print(bool final_line) {
  if (GetLogLevel() < LogLevel::kInfo) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? done_ / elapsed : 0.0;
  const double eta = rate > 0 && total_ > done_ ? (total_ - done_) / rate : 0.0;
  char line[320];
  const std::string note = note_.empty() ? "" : ", " + note_.substr(0, 48);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = total_ ? static_cast<int>(kWidth * std::min<size_t>(done_, total_) / total_) : 0;
    std::string bar(filled, '#');
    bar.resize(kWidth, '.');
    std::snprintf(line, sizeof(line), "\r%s [%s] %zu/%zu %.1f/s%s %s %s", what_.c_str(), bar.c_str(), done_, total_,
                  rate, note.c_str(), final_line ? "in" : "ETA", FormatSeconds(final_line ? elapsed : eta).c_str());
  } else {
    std::snprintf(line, sizeof(line), "%s: %zu/%zu, %.1f/s%s, %s %s", what_.c_str(), done_, total_, rate, note.c_str(),
                  final_line ? "done in" : "ETA", FormatSeconds(final_line ? elapsed : eta).c_str());
  }
  std::lock_guard<std::mutex> lock(g_stderr_mutex);
  std::cerr << line << ((final_line || !tty_) ? "\n" : "") << std::flush;
}

}  // namespace pdvo
