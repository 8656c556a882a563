// envgi: physically based rendering lit by HDR environment maps.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>

#include "cli/Commands.h"

int main(int argc, char** argv) {
  CLI::App app{"envgi: global illumination from HDR environment maps"};
  app.require_subcommand(1);
  // -v and -q also after the subcommand (envgi render scene.xml -q), as users type them; the
  // subcommands made below inherit this.
  app.fallthrough();
  app.set_version_flag("--version", std::string("envgi ") + ENVGI_VERSION);
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");
  app.add_flag("-q,--quiet", quiet, "Warnings and errors only (no progress bar)");
  app.parse_complete_callback([&] {
    spdlog::set_pattern("[%^%l%$] %v");
    spdlog::set_level(verbose ? spdlog::level::debug : (quiet ? spdlog::level::warn : spdlog::level::info));
  });
  envgi::cli::addEnvmapCommands(app);
  envgi::cli::addRenderCommand(app);
  envgi::cli::addPhotonsCommand(app);
  envgi::cli::addStudyCommand(app);
  envgi::cli::addCompareCommand(app);
  envgi::cli::addViewCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const envgi::cli::ExitStatus& e) {
    return e.code;
  } catch (const CLI::ParseError& e) {
    // One line, like every other error; --help has the details.
    std::fprintf(stderr, "envgi: error: %s (see envgi --help)\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // An allocation the system refused (past a ulimit, or far larger than its memory) is one
    // line too; the bounds envgi checks itself (film, photon maps, grid) say what to lower.
    std::fprintf(stderr, "envgi: error: out of memory: the system refused an allocation (std::bad_alloc)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "envgi: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
