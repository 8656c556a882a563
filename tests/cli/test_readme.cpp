// The README's quick start, as a new user types it: each command of its first `sh` block after
// "## Quick start" is read from README.md itself and run from a fresh folder on the bundled
// scenes, made small (-D res=16, few samples, short budgets). A command that stops working, or
// an output it promises that is not made, fails here.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli/CliRunner.h"

using namespace envgi::test;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> quickStartCommands() {
  const std::string readme = slurp(std::string(ENVGI_SOURCE_DIR) + "/README.md");
  const size_t section = readme.find("## Quick start");
  if (section == std::string::npos) return {};
  const size_t begin = readme.find("```sh\n", section), end = readme.find("```\n", begin + 6);
  if (begin == std::string::npos || end == std::string::npos) return {};
  std::vector<std::string> commands;
  std::istringstream lines(readme.substr(begin + 6, end - begin - 6));
  for (std::string line; std::getline(lines, line);) {
    line = line.substr(0, line.find(" #"));
    while (!line.empty() && line.back() == ' ') line.pop_back();
    if (line.rfind("build/bin/envgi ", 0) == 0) commands.push_back(line.substr(16));
  }
  return commands;
}

}  // namespace

TEST(Readme, TheQuickStartCommandsWork) {
  const std::vector<std::string> commands = quickStartCommands();
  ASSERT_GE(commands.size(), 5u) << "the README's quick start has five commands";
  TempDir d;
  const std::string scenes = std::string(ENVGI_SOURCE_DIR) + "/scenes/";
  for (std::string args : commands) {
    args = std::regex_replace(args, std::regex("(^| )scenes/"), "$1" + scenes);
    args = std::regex_replace(args, std::regex("--time [0-9.,]+"), "--time 0.02");
    const std::string verb = args.substr(0, args.find(' '));
    std::string shell = "cd " + d.path.string() + " && ";
    if (verb == "render") args += " -D res=16 --spp 4";
    if (verb == "study") args += " -D res=16 --spp 1,2 --reference-spp 16 --strategies importance,uniform";
    if (verb == "view") shell += "timeout -s TERM 8 ", args += " --port 0 -D res=16";
    CliResult r = runCli(args, shell);
    if (verb == "view") {
      EXPECT_NE(r.output.find("view: open http://"), std::string::npos) << args << "\n" << r.output;
      continue;
    }
    EXPECT_EQ(r.code, 0) << args << "\n" << r.output;
    // Every output the command names is there.
    std::smatch m;
    if (std::regex_search(args, m, std::regex("-o (\\S+)"))) {
      const fs::path out = d.path / m[1].str();
      EXPECT_TRUE(fs::exists(out)) << args;
      if (args.find("--png") != std::string::npos)
        EXPECT_TRUE(fs::exists(fs::path(out).replace_extension(".png"))) << args;
      if (verb == "study") EXPECT_TRUE(fs::exists(out / "report.html")) << args;
    }
  }
}
