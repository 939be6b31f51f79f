// Levelled, thread-safe logging to stderr and progress reporting for long work.
//
// The log level is the one process-wide setting (as OpenVINS' Printer); every tool sets it from --verbosity.
// Libraries log through PDVO_LOG(level) << ...; long loops report through a Progress object, which draws a
// bar with rate and ETA on a terminal and prints plain periodic lines otherwise (logs, CI).
#pragma once

#include <chrono>
#include <cstddef>
#include <sstream>
#include <string>

namespace pdvo {

enum class LogLevel { kError = 0, kWarning = 1, kInfo = 2, kDebug = 3 };

// Sets / reads the process-wide level; messages above it are dropped.
void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();
// Parses "error", "warning", "info", "debug" or 0..3; throws InvalidArgument otherwise.
LogLevel ParseLogLevel(const std::string& text);

// The process's resident memory now, in MiB (from /proc/self/statm; 0 where there is none).
double ResidentMiB();

// Lets the C library's allocator keep freed memory for reuse, up to `mib` MiB: blocks of any size come from the
// heap (not a fresh mapping each) and the heap is not given back while it is below that. The detector allocates
// tables of several MiB per image; fresh pages cost a page fault each, which on a virtual machine doubled the
// detector's time (bench/detector_bench). Call it first thing in main(); a no-op where the allocator is not glibc's.
void KeepFreedMemory(int mib = 256);

namespace detail {
// Collects one message and writes it, whole, to stderr when destroyed.
class LogMessage {
 public:
  explicit LogMessage(LogLevel level) : level_(level) {}
  ~LogMessage();
  LogMessage(const LogMessage&) = delete;
  LogMessage& operator=(const LogMessage&) = delete;
  std::ostream& stream() { return stream_; }

 private:
  LogLevel level_;
  std::ostringstream stream_;
};
}  // namespace detail

// Reports progress of `total` steps named `what`. Call Step() after each step, Finish() at the end (the
// destructor finishes too). On a terminal the bar is redrawn at most 10 times a second; otherwise a plain line
// is printed every `plain_interval_s` seconds. Nothing is printed below LogLevel::kInfo.
class Progress {
 public:
  Progress(std::string what, size_t total, double plain_interval_s = 5.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void Step(size_t n = 1);
  // A short status shown after the counts from the next line on (e.g. "state 212").
  void SetNote(std::string note) { note_ = std::move(note); }
  void Finish();
  size_t done() const { return done_; }
  // Steps per second so far.
  double Rate() const;

 private:
  void Print(bool final_line);

  std::string what_;
  std::string note_;
  size_t total_;
  size_t done_ = 0;
  double plain_interval_s_;
  bool tty_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_print_;
  int uncaught_at_start_;  // std::uncaught_exceptions() at construction
};

}  // namespace pdvo

namespace pdvo::detail {
// Turns the stream expression into void, so that PDVO_LOG works as one expression (safe in a braceless if).
struct LogVoidify {
  void operator&(std::ostream&) {}
};
}  // namespace pdvo::detail

// PDVO_LOG(Info) << "message": the message is built only if the level is enabled.
#define PDVO_LOG(level)                                \
  (::pdvo::LogLevel::k##level > ::pdvo::GetLogLevel()) \
      ? (void)0                                        \
      : ::pdvo::detail::LogVoidify() & ::pdvo::detail::LogMessage(::pdvo::LogLevel::k##level).stream()
