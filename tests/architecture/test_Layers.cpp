// The layering in docs/architecture.md, held: the table there says which layers each folder
// under src/ may include, and every #include "layer/..." in src/ must stay inside that layer's
// allowed set (its own, those it lists, and theirs in turn). The table is read from the doc,
// so the doc and the code cannot drift apart silently.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Layer -> the layers it names under "may include" ("everything": the empty set marked by "*").
std::map<std::string, std::set<std::string>> layerTable(const std::string& doc) {
  std::map<std::string, std::set<std::string>> t;
  std::regex row(R"(^\| `(\w+)` \|.*\| ([^|]*) \|\s*$)");
  std::istringstream in(doc);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    std::set<std::string>& allowed = t[m[1]];
    std::string cell = m[2];
    if (cell.find("everything") != std::string::npos) allowed.insert("*");
    std::regex name(R"(\b(\w+)\b)");
    for (auto it = std::sregex_iterator(cell.begin(), cell.end(), name); it != std::sregex_iterator(); ++it)
      if ((*it)[1] != "everything") allowed.insert((*it)[1]);
  }
  return t;
}

std::set<std::string> closure(const std::map<std::string, std::set<std::string>>& t, const std::string& layer) {
  std::set<std::string> seen{layer};
  std::vector<std::string> todo{layer};
  while (!todo.empty()) {
    std::string l = todo.back();
    todo.pop_back();
    auto it = t.find(l);
    if (it == t.end()) continue;
    for (const std::string& next : it->second)
      if (seen.insert(next).second) todo.push_back(next);
  }
  return seen;
}

}  // namespace

TEST(Architecture, NoIncludeRunsUpTheLayers) {
  const fs::path root = ENVGI_SOURCE_DIR;
  auto table = layerTable(slurp(root / "docs/architecture.md"));
  ASSERT_GE(table.size(), 10u) << "the layer table in docs/architecture.md was not found";
  ASSERT_TRUE(table.count("core") && table.count("render") && table.count("cli"));
  EXPECT_TRUE(table["core"].empty());
  EXPECT_TRUE(table["cli"].count("*"));
  std::regex include(R"re(#include "(\w+)/)re");
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(root / "src")) {
    if (!e.is_regular_file()) continue;
    fs::path rel = fs::relative(e.path(), root / "src");
    if (rel.begin() == rel.end() || std::next(rel.begin()) == rel.end()) continue;  // src/CMakeLists.txt
    std::string layer = rel.begin()->string();
    ASSERT_TRUE(table.count(layer)) << "src/" << layer << " is not in docs/architecture.md's table";
    if (table[layer].count("*")) continue;
    std::set<std::string> allowed = closure(table, layer);
    std::string text = slurp(e.path());
    for (auto it = std::sregex_iterator(text.begin(), text.end(), include); it != std::sregex_iterator(); ++it) {
      std::string to = (*it)[1];
      if (!table.count(to)) continue;  // a library's own folder (<nlohmann/...> uses <>, but be safe)
      EXPECT_TRUE(allowed.count(to)) << "src/" << rel.string() << " includes " << to << "/, above " << layer;
    }
    ++files;
  }
  EXPECT_GT(files, 50);
}
