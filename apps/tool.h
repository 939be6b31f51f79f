// What every `pdvo` subcommand shares: --verbosity, --set overrides, and the table of subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <iostream>

#include <string>
#include <vector>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/camera.h"
#include "pdvo/common/dataset.h"
#include "pdvo/common/options.h"

namespace pdvo::apps {

// Adds --verbosity (error, warning, info, debug) to a subcommand; call ApplyVerbosity after parsing.
void AddVerbosityFlag(CLI::App& app, std::string* verbosity);
void ApplyVerbosity(const std::string& verbosity);

// Parses a subcommand's flags: --help prints and returns 0; a usage error is one line and returns 1.
#define PDVO_PARSE_FLAGS(app, argc, argv)                                            \
  do {                                                                               \
    try {                                                                            \
      (app).parse((argc), (argv));                                                   \
    } catch (const CLI::CallForHelp& e) {                                            \
      return (app).exit(e);                                                          \
    } catch (const CLI::ParseError& e) {                                             \
      std::cerr << (app).get_name() << ": error: " << e.what() << " (see --help)\n"; \
      return 1;                                                                      \
    }                                                                                \
  } while (false)

// Flag values CLI11's own checks let through: a number in [lo, hi] (not NaN), and a whole number that is not
// negative (for unsigned flags, which would otherwise take "-1" as their largest value).
CLI::Validator NumberIn(double lo, double hi);
CLI::Validator NotNegative();

// Adds --config FILE and repeatable --set key=value.
void AddConfigFlags(CLI::App& app, std::string* config_path, std::vector<std::string>* overrides,
                    const std::string& config_help, const std::string& set_example);

// A tool's options: the defaults, then the section `section` of --config (if given), then the --set overrides;
// checked. Throws pdvo::Error naming the file or option at fault.
template <class Options>
Options LoadToolOptions(const std::string& config_path, const std::string& section,
                        const std::vector<std::string>& overrides) {
  Options options;
  if (!config_path.empty()) options = LoadOptions<Options>(config_path, section);
  ApplyOverrides(options, overrides);
  CheckOptionsOrThrow(options, section + " options");
  return options;
}

// The camera of a sequence: from `camera_path` if given, else the sequence's own; throws naming the file, or
// the sequence that holds none.
Camera SequenceCamera(const Sequence& sequence, const std::string& sequence_path, const std::string& camera_path);

// Every .json file among the given files and folders (folders not recursed), sorted; throws IoError for a
// missing path and FormatError for a folder without annotations.
std::vector<std::string> ListAnnotationFiles(const std::vector<std::string>& inputs);

// Subcommands: each parses its own flags, returns 0 on success and throws pdvo::Error on failure.
// The project's version and the git commit it was built from (apps/version.cpp.in).
extern const char* const kVersion;
extern const char* const kGitHash;

int RunShow(int argc, char** argv);
int RunValidate(int argc, char** argv);
int RunAnnotateDepth(int argc, char** argv);
int RunCompare(int argc, char** argv);
int RunAte(int argc, char** argv);
int RunSynth(int argc, char** argv);
int RunTrain(int argc, char** argv);
int RunEvaluate(int argc, char** argv);
int RunVo(int argc, char** argv);
int RunDetect(int argc, char** argv);
int RunEvaluateDetection(int argc, char** argv);
int RunReport(int argc, char** argv);

}  // namespace pdvo::apps
