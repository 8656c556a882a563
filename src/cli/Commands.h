// Sub-command registration for the envgi command line.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

#include "sampling/Sampler.h"

namespace envgi::cli {

void addEnvmapCommands(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addPhotonsCommand(CLI::App& app);
void addStudyCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addImageCommands(CLI::App& app);
void addViewCommand(CLI::App& app);

// Option checks whose errors read as sentences ("--spp must be at least 1, not 0"); CLI11's
// PositiveNumber names a range up to 1.8e308 and lets NaN through where the option is a float.
// The whole text as a finite number ("1x", "", "inf" and "nan" are not).
bool parseFiniteNumber(const std::string& s, double& v);
// A finite number no smaller than `lo`:
CLI::Validator atLeast(double lo);
// Any finite number:
CLI::Validator finiteNumber();
// A whole number from lo to hi:
CLI::Validator wholeNumberFrom(long long lo, long long hi);
// --threads N on a command that renders: 0 (every core) to kMaxWorkerThreads.
void addThreadsOption(CLI::App* c, int* threads);

// An output file's extension, lower-cased, checked before any work is done: one of `allowed`
// (".exr", ...), in a folder that exists and takes files; else one error naming what is written there.
std::string requireOutputExtension(const std::string& path, const std::vector<std::string>& allowed,
                                   const std::string& what);

// An image whose values are radiance (.exr, .pfm, .hdr), for a command (`who`) that measures
// error: an 8-bit file holds tone-mapped, clamped display values, whose error against radiance
// means nothing (a render's PNG against its own EXR gave RMSE 0.82).
void requireRadianceImage(const std::string& path, const std::string& who);

// A command that ends with a status of its own, its work done and said (a render stopped by
// SIGINT or SIGTERM: 128 + the signal, the shell's convention, after writing what it finished).
struct ExitStatus {
  int code;
};

// -D name=value pairs into a map; throws on a pair without '='.
std::map<std::string, std::string> parseDefines(const std::vector<std::string>& ds);

// A map strategy's name (scene/NameTables.h, map strategies only) as an EnvStrategy; throws on others.
int parseStrategyName(const std::string& name);

}  // namespace envgi::cli
