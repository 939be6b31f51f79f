// The `pdvo` command: one binary, one subcommand per job. main() turns every error into one line on stderr
// and an exit code: 1 for a usage error, 2 for a failure while running.
#include <algorithm>
#include <cstring>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "tool.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

constexpr Command kCommands[] = {
    {"show", pdvo::apps::RunShow, "draw an annotation over its image, planes tinted by their normal"},
    {"validate", pdvo::apps::RunValidate, "check annotation files against the format's rules"},
    {"annotate-depth", pdvo::apps::RunAnnotateDepth, "find planes in RGB-D depth maps and write annotations"},
    {"compare", pdvo::apps::RunCompare, "match estimated planes to reference annotations: IoU, normal angle"},
    {"synth", pdvo::apps::RunSynth, "render a synthetic urban street sequence with exact ground truth"},
    {"train", pdvo::apps::RunTrain, "train the plane recogniser on annotations into one model file"},
    {"evaluate", pdvo::apps::RunEvaluate, "region recognition accuracy and normal error of a model"},
    {"detect", pdvo::apps::RunDetect, "find the planes in single images: windows, MRF segmentation, annotations"},
    {"evaluate-detection", pdvo::apps::RunEvaluateDetection, "score detections against reference annotations"},
    {"vo", pdvo::apps::RunVo, "monocular visual odometry over a sequence, with detected planes as priors (PDVO)"},
    {"ate", pdvo::apps::RunAte, "absolute and relative trajectory error after SE(3)/Sim(3) alignment"},
    {"report", pdvo::apps::RunReport, "one HTML page of vo runs: Table I, plots, detections, the planar map in 3D"},
};

void PrintUsage(std::ostream& out) {
  out << "pdvo " << pdvo::apps::kVersion << " (" << pdvo::apps::kGitHash
      << "): planes recognised in single images as priors for monocular visual odometry\n\n"
      << "Usage: pdvo <command> [options]   (pdvo <command> --help for more)\n\n"
      << "Commands:\n";
  size_t width = 0;
  for (const Command& c : kCommands) width = std::max(width, std::strlen(c.name));
  for (const Command& c : kCommands) {
    out << "  " << c.name << std::string(width + 2 - std::strlen(c.name), ' ') << c.summary << "\n";
  }
}

std::string OneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  pdvo::RemoveStagingOnInterrupt();  // first: before any thread starts
  pdvo::KeepFreedMemory();
  if (argc < 2) {
    PrintUsage(std::cerr);
    return 1;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(std::cout);
    return 0;
  }
  if (name == "--version") {
    std::cout << "pdvo " << pdvo::apps::kVersion << " (" << pdvo::apps::kGitHash << ")\n";
    return 0;
  }
  for (const Command& c : kCommands) {
    if (name != c.name) continue;
    const std::string prefix = "pdvo " + name + ": error: ";
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const pdvo::InvalidArgument& e) {
      std::cerr << prefix << OneLine(e.what()) << "\n";
      return 1;
    } catch (const pdvo::Error& e) {
      std::cerr << prefix << OneLine(e.what()) << "\n";
      return 2;
    } catch (const cv::Exception& e) {
      std::cerr << prefix << "OpenCV: " << OneLine(e.err) << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << prefix << OneLine(e.what()) << "\n";
      return 2;
    }
  }
  std::cerr << "pdvo: unknown command '" << name << "'\n\n";
  PrintUsage(std::cerr);
  return 1;
}
