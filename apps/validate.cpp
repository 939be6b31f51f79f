// pdvo validate FILE|DIR...: checks annotation files and prints one line per problem.
#include <filesystem>
#include <iostream>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "tool.h"

namespace pdvo::apps {

std::vector<std::string> ListAnnotationFiles(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& input : inputs) {
    CheckExists(input, "annotation file or folder");
    if (!std::filesystem::is_directory(input)) {
      files.push_back(input);
      continue;
    }
    std::vector<std::string> here;
    for (const auto& e : std::filesystem::directory_iterator(input)) {
      if (e.is_regular_file() && e.path().extension() == ".json") here.push_back(e.path().string());
    }
    PDVO_THROW_CHECK(!here.empty(), FormatError, input << ": folder holds no .json annotation files");
    std::sort(here.begin(), here.end());
    files.insert(files.end(), here.begin(), here.end());
  }
  return files;
}

int RunValidate(int argc, char** argv) {
  CLI::App app(
      "Checks annotation files against the rules of the format (ANNOTATIONS.md) and prints one line per "
      "error or warning. Exits with 2 if any file has an error.",
      "pdvo validate");
  std::vector<std::string> inputs;
  std::string verbosity = "info";
  app.add_option("inputs", inputs, "Annotation files or folders of them")->required();
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  int errors = 0, warnings = 0;
  const std::vector<std::string> files = ListAnnotationFiles(inputs);
  for (const std::string& file : files) {
    try {
      const Annotation a = ReadAnnotation(file);
      for (const ValidationIssue& issue : Validate(a)) {
        std::cout << (issue.is_error ? "error: " : "warning: ") << FormatIssue(issue, a, file) << "\n";
        (issue.is_error ? errors : warnings)++;
      }
    } catch (const Error& e) {
      std::cout << "error: " << e.what() << "\n";
      ++errors;
    }
  }
  PDVO_LOG(Info) << files.size() << " files: " << errors << " errors, " << warnings << " warnings";
  return errors > 0 ? 2 : 0;
}

}  // namespace pdvo::apps
