// What every `pdvo` subcommand shares: --verbosity, --set overrides, and the table of subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace pdvo::apps {

// Adds --verbosity (error, warning, info, debug) to a subcommand; call ApplyVerbosity after parsing.
void AddVerbosityFlag(CLI::App& app, std::string* verbosity);
void ApplyVerbosity(const std::string& verbosity);

// Subcommands: each parses its own flags, returns 0 on success and throws pdvo::Error on failure.
int RunShow(int argc, char** argv);
int RunValidate(int argc, char** argv);
int RunAnnotateDepth(int argc, char** argv);
int RunCompare(int argc, char** argv);
int RunAte(int argc, char** argv);

}  // namespace pdvo::apps
