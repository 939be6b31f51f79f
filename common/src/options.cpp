#include "pdvo/common/options.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "pdvo/common/file_io.h"

namespace pdvo {
namespace detail {

std::string& FailedOption() {
  thread_local std::string failed;
  return failed;
}

std::string ValueText(bool value) { return value ? "true" : "false"; }
std::string ValueText(int value) { return std::to_string(value); }
std::string ValueText(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}
std::string ValueText(const std::string& value) { return "'" + value + "'"; }
std::string ValueText(const std::vector<double>& value) {
  std::string out = "[";
  for (size_t i = 0; i < value.size(); ++i) out += (i ? ", " : "") + ValueText(value[i]);
  return out + "]";
}

bool MentionsIdentifier(const std::string& text, const std::string& name) {
  auto part = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    const size_t end = at + name.size();
    if ((at == 0 || !part(text[at - 1])) && (end == text.size() || !part(text[end]))) return true;
  }
  return false;
}

namespace {
std::string TypeName(const cv::FileNode& node) {
  if (node.isMap()) return "a map";
  if (node.isSeq()) return "a list";
  if (node.isString()) return "text '" + node.string() + "'";
  return "a number";
}

double ParseDouble(const std::string& text, const std::string& where) {
  double v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  PDVO_THROW_CHECK(ec == std::errc() && ptr == end, InvalidArgument,
                   where << ": expected a number, got '" << text << "'");
  PDVO_THROW_CHECK(std::isfinite(v), InvalidArgument, where << ": expected a finite number, got '" << text << "'");
  return v;
}
}  // namespace

void ReadScalar(const cv::FileNode& node, const std::string& where, bool& value) {
  if (node.isInt()) {
    value = static_cast<int>(node) != 0;
    return;
  }
  PDVO_THROW_CHECK(node.isString(), FormatError, where << ": expected true or false, got " << TypeName(node));
  ParseScalar(node.string(), where, value);
}

void ReadScalar(const cv::FileNode& node, const std::string& where, int& value) {
  PDVO_THROW_CHECK(node.isInt(), FormatError, where << ": expected an integer, got " << TypeName(node));
  value = static_cast<int>(node);
}

void ReadScalar(const cv::FileNode& node, const std::string& where, double& value) {
  PDVO_THROW_CHECK(node.isInt() || node.isReal(), FormatError, where << ": expected a number, got " << TypeName(node));
  value = static_cast<double>(node);
  PDVO_THROW_CHECK(std::isfinite(value), FormatError, where << ": expected a finite number, got " << value);
}

void ReadScalar(const cv::FileNode& node, const std::string& where, std::string& value) {
  PDVO_THROW_CHECK(node.isString(), FormatError, where << ": expected text, got " << TypeName(node));
  value = node.string();
}

void ReadScalar(const cv::FileNode& node, const std::string& where, std::vector<double>& value) {
  PDVO_THROW_CHECK(node.isSeq(), FormatError, where << ": expected a list of numbers, got " << TypeName(node));
  std::vector<double> read;
  for (const cv::FileNode& item : node) {
    PDVO_THROW_CHECK(item.isInt() || item.isReal(), FormatError,
                     where << ": expected a list of numbers, found " << TypeName(item));
    read.push_back(static_cast<double>(item));
    PDVO_THROW_CHECK(std::isfinite(read.back()), FormatError,
                     where << ": expected a list of finite numbers, found " << read.back());
  }
  value = std::move(read);
}

void WriteScalar(cv::FileStorage& fs, const char* key, const bool& value) { fs << key << (value ? "true" : "false"); }
void WriteScalar(cv::FileStorage& fs, const char* key, const int& value) { fs << key << value; }
void WriteScalar(cv::FileStorage& fs, const char* key, const double& value) { fs << key << value; }
void WriteScalar(cv::FileStorage& fs, const char* key, const std::string& value) { fs << key << value; }
void WriteScalar(cv::FileStorage& fs, const char* key, const std::vector<double>& value) {
  fs << key << "[:";
  for (double v : value) fs << v;
  fs << "]";
}

void ParseScalar(const std::string& text, const std::string& where, bool& value) {
  if (text == "true" || text == "1") {
    value = true;
  } else if (text == "false" || text == "0") {
    value = false;
  } else {
    PDVO_THROW(InvalidArgument, where << ": expected true or false, got '" << text << "'");
  }
}

void ParseScalar(const std::string& text, const std::string& where, int& value) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  PDVO_THROW_CHECK(ec == std::errc() && ptr == end, InvalidArgument,
                   where << ": expected an integer, got '" << text << "'");
}

void ParseScalar(const std::string& text, const std::string& where, double& value) { value = ParseDouble(text, where); }

void ParseScalar(const std::string& text, const std::string&, std::string& value) { value = text; }

void ParseScalar(const std::string& text, const std::string& where, std::vector<double>& value) {
  // Numbers separated by commas, with or without the brackets and spaces the options files write: 1,2 or [1, 2].
  auto trim = [](const std::string& t) {
    const size_t first = t.find_first_not_of(" \t"), last = t.find_last_not_of(" \t");
    return first == std::string::npos ? std::string() : t.substr(first, last - first + 1);
  };
  std::string list = trim(text);
  if (list.size() >= 2 && list.front() == '[' && list.back() == ']') list = trim(list.substr(1, list.size() - 2));
  std::vector<double> parsed;  // assigned only when every item is a number: a failed override changes nothing
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) parsed.push_back(ParseDouble(trim(item), where));
  value = std::move(parsed);
}

void ThrowIfUnknownKeys(const cv::FileNode& node, const std::set<std::string>& known, const std::string& where) {
  for (const std::string& key : node.keys()) {
    if (known.count(key)) continue;
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    PDVO_THROW(FormatError, where << ": unknown key '" << key << "' (known keys: " << list << ")");
  }
}
}  // namespace detail

cv::FileStorage OpenYamlText(const std::string& text, const std::string& where) {
  CheckYamlText(text, where);
  cv::FileStorage fs;
  try {
    fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    // OpenCV takes YAML only after its header line, and says so as an unsupported format.
    PDVO_THROW_CHECK(text.starts_with("%YAML"), FormatError,
                     where << ": OpenCV's YAML reader needs the header line %YAML:1.0 (then ---) first");
    PDVO_THROW(FormatError, where << ": not valid YAML (" << e.err << ")");
  } catch (const std::length_error& e) {  // OpenCV's parser on some malformed keys (found by fuzzing)
    PDVO_THROW(FormatError, where << ": not valid YAML (OpenCV's parser failed: " << e.what() << ")");
  }
  PDVO_THROW_CHECK(fs.isOpened(), FormatError, where << ": cannot open as YAML");
  // OpenCV's parser does not always read what libyaml reads (e.g. "-a : b" is a map to one, a list to the other).
  PDVO_THROW_CHECK(fs.root().isMap(), FormatError, where << ": not a YAML map of keys (as OpenCV reads it)");
  return fs;
}

cv::FileStorage OpenYamlForReading(const std::string& path) {
  CheckExists(path);
  return OpenYamlText(ReadFile(path), path);
}

}  // namespace pdvo
