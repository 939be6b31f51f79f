// Options structs read from and written to YAML (cv::FileStorage), with unknown keys treated as errors.
//
// An options struct keeps its defaults in-class and lists its fields once, in a static visitor:
//
//   struct FooOptions {
//     double max_angle_deg = 15.0;  // degrees
//     BarOptions bar;               // nested options become a nested YAML map
//     template <class Self, class V> static void Fields(Self& self, V& visit) {
//       visit("max_angle_deg", self.max_angle_deg);
//       visit("bar", self.bar);
//     }
//     bool Check() const;           // records the failed condition and returns false (COLMAP's CHECK_OPTION)
//     bool operator==(const FooOptions&) const = default;
//   };
//
// From that one list come reading (absent keys keep their defaults; unknown keys and wrong types throw
// FormatError naming the file and the key), writing, and `--set key.sub=value` overrides.
// Field types: bool, int, double, std::string, std::vector<double>, nested options structs, and enums that
// name their values with a function found by argument-dependent lookup, as text in YAML and in `--set`:
//
//   enum class Shape { kSquare, kRound };
//   constexpr std::array<std::pair<Shape, const char*>, 2> OptionNames(Shape) {
//     return {{{Shape::kSquare, "square"}, {Shape::kRound, "round"}}};
//   }
#pragma once

#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"

namespace pdvo {

namespace detail {
struct FieldProbe {
  template <class T>
  void operator()(const char*, T&) {}
};
}  // namespace detail

template <class T>
concept OptionsStruct = requires(T& t, detail::FieldProbe& probe) {
  T::Fields(t, probe);
};

// An enum whose values have names (OptionNames, above).
template <class T>
concept OptionsEnum = std::is_enum_v<T> && requires(T t) {
  OptionNames(t);
};

// The name of an enum value, and the value of a name (InvalidArgument naming `where` and the names if unknown).
template <OptionsEnum T>
std::string OptionName(T value) {
  for (const auto& [v, name] : OptionNames(value)) {
    if (v == value) return name;
  }
  return "?";
}
template <OptionsEnum T>
T OptionValue(const std::string& text, const std::string& where) {
  std::string names;
  for (const auto& [v, name] : OptionNames(T{})) {
    if (text == name) return v;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  PDVO_THROW(InvalidArgument, where << ": '" << text << "' is not one of " << names);
}

namespace detail {
// The first condition that failed in a PDVO_CHECK_OPTION since it was last cleared (per thread): the innermost
// one when Check() calls nested Check()s.
std::string& FailedOption();
}  // namespace detail

// In a Check(): records the failed condition (see detail::FailedOption) and returns false.
#define PDVO_CHECK_OPTION(cond)                                                           \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      if (::pdvo::detail::FailedOption().empty()) ::pdvo::detail::FailedOption() = #cond; \
      return false;                                                                       \
    }                                                                                     \
  } while (false)

namespace detail {
void ReadScalar(const cv::FileNode& node, const std::string& where, bool& value);
void ReadScalar(const cv::FileNode& node, const std::string& where, int& value);
void ReadScalar(const cv::FileNode& node, const std::string& where, double& value);
void ReadScalar(const cv::FileNode& node, const std::string& where, std::string& value);
void ReadScalar(const cv::FileNode& node, const std::string& where, std::vector<double>& value);
void WriteScalar(cv::FileStorage& fs, const char* key, const bool& value);
void WriteScalar(cv::FileStorage& fs, const char* key, const int& value);
void WriteScalar(cv::FileStorage& fs, const char* key, const double& value);
void WriteScalar(cv::FileStorage& fs, const char* key, const std::string& value);
void WriteScalar(cv::FileStorage& fs, const char* key, const std::vector<double>& value);
void ParseScalar(const std::string& text, const std::string& where, bool& value);
void ParseScalar(const std::string& text, const std::string& where, int& value);
void ParseScalar(const std::string& text, const std::string& where, double& value);
void ParseScalar(const std::string& text, const std::string& where, std::string& value);
void ParseScalar(const std::string& text, const std::string& where, std::vector<double>& value);
void ThrowIfUnknownKeys(const cv::FileNode& node, const std::set<std::string>& known, const std::string& where);
}  // namespace detail

// Reads the fields of `options` from a YAML map; `where` names the file (and section) for error messages.
template <OptionsStruct T>
void ReadOptions(const cv::FileNode& node, T& options, const std::string& where) {
  if (node.empty() || node.isNone()) return;
  PDVO_THROW_CHECK(node.isMap(), FormatError, where << ": expected a map of options");
  std::set<std::string> known;
  auto visit = [&](const char* key, auto& field) {
    known.insert(key);
    const cv::FileNode child = node[key];
    if (child.empty() || child.isNone()) return;
    const std::string child_where = where + "." + key;
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (OptionsStruct<Field>) {
      ReadOptions(child, field, child_where);
    } else if constexpr (OptionsEnum<Field>) {
      std::string text;
      detail::ReadScalar(child, child_where, text);
      try {
        field = OptionValue<Field>(text, child_where);
      } catch (const InvalidArgument& e) {
        PDVO_THROW(FormatError, e.what());
      }
    } else {
      detail::ReadScalar(child, child_where, field);
    }
  };
  T::Fields(options, visit);
  detail::ThrowIfUnknownKeys(node, known, where);
}

// Writes the fields of `options` into the currently open map of `fs`.
template <OptionsStruct T>
void WriteOptions(cv::FileStorage& fs, const T& options) {
  auto visit = [&](const char* key, const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (OptionsStruct<Field>) {
      fs << key << "{";
      WriteOptions(fs, field);
      fs << "}";
    } else if constexpr (OptionsEnum<Field>) {
      detail::WriteScalar(fs, key, OptionName(field));
    } else {
      detail::WriteScalar(fs, key, field);
    }
  };
  T::Fields(options, visit);
}

// Sets one field from text: key "a.b.c" names a nested field. Throws InvalidArgument for an unknown key or an
// unparsable value.
template <OptionsStruct T>
void SetOption(T& options, const std::string& key, const std::string& value) {
  const size_t dot = key.find('.');
  const std::string head = key.substr(0, dot);
  bool found = false;
  auto visit = [&](const char* name, auto& field) {
    if (head != name) return;
    found = true;
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (OptionsStruct<Field>) {
      PDVO_THROW_CHECK(dot != std::string::npos, InvalidArgument,
                       "option '" << key << "' is a group; name one of its fields");
      SetOption(field, key.substr(dot + 1), value);
    } else {
      PDVO_THROW_CHECK(dot == std::string::npos, InvalidArgument, "unknown option '" << key << "'");
      if constexpr (OptionsEnum<Field>) {
        field = OptionValue<Field>(value, key);
      } else {
        detail::ParseScalar(value, key, field);
      }
    }
  };
  T::Fields(options, visit);
  PDVO_THROW_CHECK(found, InvalidArgument, "unknown option '" << key << "'");
}

// Applies "key=value" overrides (from repeated --set flags).
template <OptionsStruct T>
void ApplyOverrides(T& options, const std::vector<std::string>& assignments) {
  for (const std::string& a : assignments) {
    const size_t eq = a.find('=');
    PDVO_THROW_CHECK(eq != std::string::npos && eq > 0, InvalidArgument, "--set expects key=value, got '" << a << "'");
    SetOption(options, a.substr(0, eq), a.substr(eq + 1));
  }
}

// Throws FormatError naming `where` unless `text` may be given to OpenCV's YAML parser, which hangs or overflows
// its stack on some malformed or deeply nested files (OpenCV 4.6): well-formed YAML as libyaml reads it, a map at
// the top, nested at most kMaxYamlDepth levels, at most kMaxYamlBytes. OpenCV's header line (%YAML:1.0) is taken.
inline constexpr int kMaxYamlDepth = 64;
inline constexpr size_t kMaxYamlBytes = size_t{256} << 20;
void CheckYamlText(const std::string& text, const std::string& where);

// Returns read() (code that reads a cv::FileStorage), with an OpenCV error turned into a FormatError naming
// `where`: OpenCV asserts on some malformed values, e.g. a matrix whose data does not match its size.
template <class Read>
auto WithOpenCvErrorsNamed(const std::string& where, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const cv::Exception& e) {
    PDVO_THROW(FormatError, where << ": malformed (OpenCV: " << e.err << ")");
  }
}

// Opens YAML text (read from `where`) after CheckYamlText has passed it; throws FormatError naming `where` if it is
// not valid YAML or its top level is not a map of keys. The one way the project hands YAML to OpenCV.
cv::FileStorage OpenYamlText(const std::string& text, const std::string& where);
// OpenYamlText on a file's content; IoError naming the file if it cannot be read.
cv::FileStorage OpenYamlForReading(const std::string& path);

namespace detail {
std::string ValueText(bool value);
std::string ValueText(int value);
std::string ValueText(double value);
std::string ValueText(const std::string& value);
std::string ValueText(const std::vector<double>& value);
// True if `name` stands in `text` as a whole identifier.
bool MentionsIdentifier(const std::string& text, const std::string& name);

// "a.b = value" for each field whose name the condition mentions (the same name in several groups: each).
template <OptionsStruct T>
void MentionedValues(const T& options, const std::string& condition, const std::string& prefix,
                     std::vector<std::string>* out) {
  auto visit = [&](const char* key, const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (OptionsStruct<Field>) {
      MentionedValues(field, condition, prefix + key + ".", out);
    } else if (MentionsIdentifier(condition, key)) {
      if constexpr (OptionsEnum<Field>) {
        out->push_back(prefix + key + " = " + OptionName(field));
      } else {
        out->push_back(prefix + key + " = " + ValueText(field));
      }
    }
  };
  T::Fields(options, visit);
}
}  // namespace detail

// Every field as "a.b=value", the form --set takes (a record of the options a result was made with).
template <OptionsStruct T>
void OptionAssignments(const T& options, std::vector<std::string>* out, const std::string& prefix = "") {
  auto visit = [&](const char* key, const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (OptionsStruct<Field>) {
      OptionAssignments(field, out, prefix + key + ".");
    } else if constexpr (OptionsEnum<Field>) {
      out->push_back(prefix + key + "=" + OptionName(field));
    } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
      std::string list;
      for (const double v : field) {
        if (!list.empty()) list += ',';
        list += detail::ValueText(v);
      }
      out->push_back(prefix + key + "=" + list);
    } else if constexpr (std::is_same_v<Field, std::string>) {
      out->push_back(prefix + key + "=" + field);
    } else {
      out->push_back(prefix + key + "=" + detail::ValueText(field));
    }
  };
  T::Fields(options, visit);
}

// Throws InvalidArgument if options.Check() fails, naming the options (`what`), the failed condition and the
// values of the options it names, e.g. "invalid vo options: search.min_ncc > -1 && ... does not hold
// (search.min_ncc = 1.5)".
template <OptionsStruct T>
void CheckOptionsOrThrow(const T& options, const std::string& what) {
  detail::FailedOption().clear();
  if (options.Check()) return;
  const std::string condition = detail::FailedOption();
  std::vector<std::string> values;
  detail::MentionedValues(options, condition, "", &values);
  std::string listed;
  for (const std::string& v : values) listed += (listed.empty() ? " (" : ", ") + v;
  PDVO_THROW(InvalidArgument,
             "invalid " << what << ": " << condition << " does not hold" << listed << (listed.empty() ? "" : ")"));
}

// Reads options from the map `section` of a YAML file (the root map if section is empty) and checks them; throws
// FormatError naming the file for values that fail the check.
template <OptionsStruct T>
T LoadOptions(const std::string& path, const std::string& section = "") {
  cv::FileStorage fs = OpenYamlForReading(path);
  T options;
  WithOpenCvErrorsNamed(path, [&] {
    ReadOptions(section.empty() ? fs.root() : fs[section], options, section.empty() ? path : path + ": " + section);
  });
  try {
    CheckOptionsOrThrow(options, "options in " + path);
  } catch (const InvalidArgument& e) {  // a file's fault: a data error
    PDVO_THROW(FormatError, e.what());
  }
  return options;
}

// Writes options as the map `section` of a new YAML file, atomically.
template <OptionsStruct T>
void SaveOptions(const std::string& path, const T& options, const std::string& section) {
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << section << "{";
  WriteOptions(fs, options);
  fs << "}";
  WriteFileAtomically(path, fs.releaseAndGetString());
}

}  // namespace pdvo
