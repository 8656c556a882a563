// envgi: physically based rendering lit by HDR environment maps.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>

#include <string>
#include <vector>

#include "cli/Commands.h"
#include "scene/MitsubaPlugins.h"

namespace {

// What a parse error misses for a misspelt word: the command or option not known, and the
// nearest known name (as XML properties get: " (did you mean 'render'?)").
std::string nearestNameHint(CLI::App& app, int argc, char** argv) {
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) commands.push_back(sub->get_name());
  CLI::App* command = nullptr;
  for (int i = 1; i < argc && !command; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') continue;
    if (std::find(commands.begin(), commands.end(), word) == commands.end())
      return "; unknown command '" + word + "'" + envgi::didYouMean(word, commands);
    command = app.get_subcommand(word);
  }
  if (!command) return "";
  std::vector<std::string> options;
  for (const CLI::App* a : {static_cast<const CLI::App*>(&app), static_cast<const CLI::App*>(command)})
    for (const CLI::Option* o : a->get_options()) {
      for (const std::string& l : o->get_lnames()) options.push_back("--" + l);
      for (const std::string& n : o->get_snames()) options.push_back("-" + n);
    }
  for (int i = 1; i < argc; ++i) {
    std::string word = argv[i];
    if (word.size() < 2 || word[0] != '-' || (word[1] >= '0' && word[1] <= '9') || word[1] == '.') continue;
    word = word.substr(0, word.find('='));
    bool known = false;
    for (const std::string& o : options) known = known || o == word;
    // -D name=value and the like: a short option's value may follow it in the same word.
    if (!known && word.size() > 2 && word[1] != '-')
      for (const std::string& o : options) known = known || (o.size() == 2 && word.rfind(o, 0) == 0);
    if (!known) return "; unknown option '" + word + "'" + envgi::didYouMean(word, options);
  }
  return "";
}

}  // namespace

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
  envgi::cli::addImageCommands(app);
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
    std::fprintf(stderr, "envgi: error: %s%s (see envgi --help)\n", e.what(), nearestNameHint(app, argc, argv).c_str());
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
