// The check before OpenCV's YAML parser sees a file (options.h: CheckYamlText), with libyaml's event parser,
// which keeps its own stack and so neither recurses nor hangs.
#include <yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string_view>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {

int Base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  return c == '+' ? 62 : c == '/' ? 63 : -1;
}

// Whether `value` (a !!binary scalar) is what OpenCV writes for a matrix: base64 whose first 24 bytes are the
// element type ("1f", "3d", "2i1f", ...) padded with spaces. OpenCV's reader loops without end on some other
// headers (found by fuzzing).
bool IsOpenCvBase64(std::string_view value) {
  std::string digits;  // the base64 characters, without line breaks, spaces and padding
  for (const char c : value) {
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (c == '=') break;
    if (Base64Value(c) < 0) return false;
    digits += c;
  }
  if (digits.size() < 32) return false;
  std::string header;
  for (size_t i = 0; i < 32; i += 4) {
    const int v = Base64Value(digits[i]) << 18 | Base64Value(digits[i + 1]) << 12 | Base64Value(digits[i + 2]) << 6 |
                  Base64Value(digits[i + 3]);
    for (const int shift : {16, 8, 0}) header += static_cast<char>(v >> shift & 255);
  }
  // One or more of (an optional count, then a type letter), then padding: "1f", "3d", "iif".
  constexpr std::string_view kTypes = "ucwsifdhr";
  size_t at = 0, groups = 0;
  while (at < header.size() && header[at] != ' ' && header[at] != '\0') {
    while (at < header.size() && std::isdigit(static_cast<unsigned char>(header[at]))) ++at;
    if (at == header.size() || kTypes.find(header[at]) == std::string_view::npos) return false;
    ++at, ++groups;
  }
  while (at < header.size() && (header[at] == ' ' || header[at] == '\0')) ++at;
  return groups > 0 && at == header.size();
}

// The number of elements an OpenCV matrix map (!!opencv-matrix: rows, cols; !!opencv-nd-matrix: sizes) declares,
// followed through the parser's events: OpenCV allocates a matrix of that size before it reads the data, so a
// matrix larger than its file could hold is refused first (fuzzing declared 10^11 elements in a 24 KB file).
struct MatrixSize {
  int depth = -1;                                          // the depth of the matrix map's keys; -1: not in one
  bool key_next = true, in_sizes = false, closed = false;  // closed: by the event taken last
  size_t line = 0;                                         // where the matrix starts
  std::string key;
  double elements = 0;  // of the matrix read last or being read

  // One event, at `depth` (before the event changes it).
  void Take(yaml_event_type_t type, const std::string& tag, const std::string& value, int at, size_t at_line) {
    closed = false;
    const auto factor = [&] {  // a size must be a whole number (OpenCV reads "~" as a huge one)
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      const bool whole = !value.empty() && end && *end == '\0' && v >= 0 && v == std::floor(v);
      return whole ? std::max(1.0, v) : std::numeric_limits<double>::infinity();
    };
    if (depth < 0) {
      if (type == YAML_MAPPING_START_EVENT && tag.rfind("tag:yaml.org,2002:opencv-", 0) == 0) {
        *this = MatrixSize();
        depth = at + 1, elements = 1, line = at_line;
      }
      return;
    }
    if (at == depth) {
      if (type == YAML_MAPPING_END_EVENT) {
        depth = -1, closed = true;
      } else if (type == YAML_SCALAR_EVENT && key_next) {
        key = value, key_next = false;
      } else {  // a value
        if (type == YAML_SCALAR_EVENT && (key == "rows" || key == "cols")) elements *= factor();
        in_sizes = type == YAML_SEQUENCE_START_EVENT && key == "sizes";
        key_next = true;
      }
    } else if (in_sizes && at == depth + 1 && type == YAML_SCALAR_EVENT) {
      elements *= factor();
    }
  }
};

}  // namespace

void CheckYamlText(const std::string& text, const std::string& where) {
  PDVO_THROW_CHECK(
      text.size() <= kMaxYamlBytes, FormatError,
      where << ": " << text.size() << " bytes, more than the " << kMaxYamlBytes << " a YAML file may have");
  // OpenCV's header line ("%YAML:1.0") is not a YAML directive: left out (its line kept, for the line numbers).
  std::string body = text;
  if (body.rfind("%YAML:", 0) == 0) body.erase(0, std::min(body.find('\n'), body.size()));
  yaml_parser_t parser;
  PDVO_THROW_CHECK(yaml_parser_initialize(&parser), Error, where << ": cannot start a YAML parser");
  const std::unique_ptr<yaml_parser_t, void (*)(yaml_parser_t*)> owner(&parser, yaml_parser_delete);
  yaml_parser_set_input_string(&parser, reinterpret_cast<const unsigned char*>(body.data()), body.size());
  int depth = 0, documents = 0;
  bool top = true;  // the next node is the document's top level
  MatrixSize matrix;
  for (;;) {
    yaml_event_t event;
    PDVO_THROW_CHECK(yaml_parser_parse(&parser, &event), FormatError,
                     where << ": not valid YAML (line " << parser.problem_mark.line + 1 << ": "
                           << (parser.problem ? parser.problem : "unreadable") << ")");
    const yaml_event_type_t type = event.type;
    const auto text_of = [](const yaml_char_t* chars) {
      return chars ? std::string(reinterpret_cast<const char*>(chars)) : std::string();
    };
    const std::string tag = type == YAML_SCALAR_EVENT          ? text_of(event.data.scalar.tag)
                            : type == YAML_MAPPING_START_EVENT ? text_of(event.data.mapping_start.tag)
                                                               : std::string();
    const std::string value =
        type == YAML_SCALAR_EVENT
            ? std::string(reinterpret_cast<const char*>(event.data.scalar.value), event.data.scalar.length)
            : std::string();
    const size_t line = event.start_mark.line + 1;
    yaml_event_delete(&event);
    PDVO_THROW_CHECK(
        tag != "tag:yaml.org,2002:binary" || IsOpenCvBase64(value), FormatError,
        where << ": line " << line << ": binary data that is not an OpenCV matrix's (base64 with its type)");
    matrix.Take(type, tag, value, depth, line);
    if (matrix.closed && !(matrix.elements <= static_cast<double>(text.size()))) {
      char elements[32];
      std::snprintf(elements, sizeof elements, "%.0f", matrix.elements);
      PDVO_THROW(FormatError,
                 where << ": line " << matrix.line << ": a matrix of "
                       << (std::isinf(matrix.elements) ? std::string("a size that is not a whole number")
                                                       : std::string(elements) + " elements, more than the file's " +
                                                             std::to_string(text.size()) + " bytes could hold"));
    }
    if (type == YAML_STREAM_END_EVENT) break;
    if (top && (type == YAML_SCALAR_EVENT || type == YAML_SEQUENCE_START_EVENT || type == YAML_ALIAS_EVENT)) {
      PDVO_THROW(FormatError, where << ": not a YAML map of keys at the top");
    }
    if (type == YAML_MAPPING_START_EVENT || type == YAML_SEQUENCE_START_EVENT) {
      top = false;
      PDVO_THROW_CHECK(++depth <= kMaxYamlDepth, FormatError,
                       where << ": YAML nested deeper than " << kMaxYamlDepth << " levels");
    }
    if (type == YAML_MAPPING_END_EVENT || type == YAML_SEQUENCE_END_EVENT) --depth;
    if (type == YAML_DOCUMENT_START_EVENT) {
      // The project's files are one document; OpenCV 4.6's reader never returns on some with two (found by fuzzing).
      PDVO_THROW_CHECK(++documents == 1, FormatError, where << ": line " << line << ": a second YAML document");
      top = true;
    }
  }
}

}  // namespace pdvo
