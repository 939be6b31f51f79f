// The check before OpenCV's YAML parser sees a file (options.h: CheckYamlText), with libyaml's event parser,
// which keeps its own stack and so neither recurses nor hangs.
#include <yaml.h>

#include <memory>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {

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
    yaml_event_delete(&event);
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
