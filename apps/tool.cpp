#include "tool.h"

#include <opencv2/core/utils/logger.hpp>
#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"

namespace pdvo::apps {

CLI::Validator NumberIn(double lo, double hi) {
  std::ostringstream range;
  range << "a number from " << lo << " to " << hi;
  return CLI::Validator(
      [lo, hi, what = range.str()](std::string& text) {
        double v = 0;
        std::istringstream in(text);
        const bool number = static_cast<bool>(in >> v) && (in >> std::ws).eof();
        return number && v >= lo && v <= hi ? std::string() : "must be " + what + ", got " + text;
      },
      range.str());
}

CLI::Validator NotNegative() {
  return CLI::Validator(
      [](std::string& text) {
        return text.find('-') == std::string::npos ? std::string() : "must not be negative, got " + text;
      },
      "NOT NEGATIVE");
}

void AddVerbosityFlag(CLI::App& app, std::string* verbosity) {
  app.add_option("--verbosity,-v", *verbosity, "Log level: error, warning, info or debug")->capture_default_str();
}

void AddConfigFlags(CLI::App& app, std::string* config_path, std::vector<std::string>* overrides,
                    const std::string& config_help, const std::string& set_example) {
  app.add_option("--config", *config_path, config_help);
  app.add_option("--set", *overrides, "Override an option, e.g. --set " + set_example);
}

void ApplyVerbosity(const std::string& verbosity) {
  const LogLevel level = ParseLogLevel(verbosity);
  SetLogLevel(level);
  // OpenCV's own messages would break the one-line errors; they are shown only when debugging.
  cv::utils::logging::setLogLevel(level == LogLevel::kDebug ? cv::utils::logging::LOG_LEVEL_WARNING
                                                            : cv::utils::logging::LOG_LEVEL_SILENT);
}

Camera SequenceCamera(const Sequence& sequence, const std::string& sequence_path, const std::string& camera_path) {
  if (!camera_path.empty()) return Camera::Read(camera_path);
  PDVO_THROW_CHECK(sequence.camera().has_value(), InvalidArgument,
                   sequence_path << ": holds no camera.yaml; pass --camera");
  return *sequence.camera();
}

}  // namespace pdvo::apps
