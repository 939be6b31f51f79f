#include "tool.h"

#include "pdvo/common/logging.h"

namespace pdvo::apps {

void AddVerbosityFlag(CLI::App& app, std::string* verbosity) {
  app.add_option("--verbosity,-v", *verbosity, "Log level: error, warning, info or debug")
      ->capture_default_str();
}

void ApplyVerbosity(const std::string& verbosity) { SetLogLevel(ParseLogLevel(verbosity)); }

}  // namespace pdvo::apps
