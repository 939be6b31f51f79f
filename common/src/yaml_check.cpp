// The check before OpenCV's YAML parser sees a file (options.h: CheckYamlText), with libyaml's event parser,
// which keeps its own stack and so neither recurses nor hangs.
#include <yaml.h>

#include <cctype>
#include <memory>
#include <regex>
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
    header += static_cast<char>(v >> 16 & 255), header += static_cast<char>(v >> 8 & 255),
        header += static_cast<char>(v & 255);
  }
  static const std::regex kHeader("([0-9]*[ucwsifdhr])+[ \\0]*");
  return std::regex_match(header, kHeader);
}

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
  int depth = 0;
  bool top = true;  // the next node is the document's top level
  for (;;) {
    yaml_event_t event;
    PDVO_THROW_CHECK(yaml_parser_parse(&parser, &event), FormatError,
                     where << ": not valid YAML (line " << parser.problem_mark.line + 1 << ": "
                           << (parser.problem ? parser.problem : "unreadable") << ")");
    const yaml_event_type_t type = event.type;
    const bool binary =
        type == YAML_SCALAR_EVENT && event.data.scalar.tag &&
        std::string_view(reinterpret_cast<const char*>(event.data.scalar.tag)) == "tag:yaml.org,2002:binary";
    const bool readable =
        !binary || IsOpenCvBase64(std::string_view(reinterpret_cast<const char*>(event.data.scalar.value),
                                                   event.data.scalar.length));
    const size_t line = event.start_mark.line + 1;
    yaml_event_delete(&event);
    PDVO_THROW_CHECK(
        readable, FormatError,
        where << ": line " << line << ": binary data that is not an OpenCV matrix's (base64 with its type)");
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
    if (type == YAML_DOCUMENT_START_EVENT) top = true;
  }
}

}  // namespace pdvo
