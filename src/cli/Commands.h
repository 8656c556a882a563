// Sub-command registration for the envgi command line.
#pragma once

#include <CLI/CLI.hpp>

namespace envgi::cli {

void addEnvmapCommands(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addPhotonsCommand(CLI::App& app);

// Parses a strategy name (uniform|cosine|importance|alias|adaptive); throws on others.
int parseStrategyName(const std::string& name);

}  // namespace envgi::cli
