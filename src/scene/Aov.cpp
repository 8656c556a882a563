#include "scene/Aov.h"

#include <set>
#include <stdexcept>

#include "scene/MitsubaPlugins.h"
#include "scene/NameTables.h"

namespace envgi {

namespace {

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\n"), b = s.find_last_not_of(" \t\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

}  // namespace

std::vector<Aov> parseAovs(const std::string& spec) {
  std::vector<Aov> out;
  std::set<std::string> channels = {"R", "G", "B"};
  size_t start = 0;
  while (start <= spec.size()) {
    size_t comma = spec.find(',', start);
    std::string item = trim(spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    start = comma == std::string::npos ? spec.size() + 1 : comma + 1;
    if (item.empty()) {
      if (spec.find_first_not_of(" \t\n,") == std::string::npos) break;  // "" asks for none
      throw std::runtime_error("AOV list '" + spec + "' has an empty entry");
    }
    size_t colon = item.find(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == item.size() || item.find(':', colon + 1) != std::string::npos)
      throw std::runtime_error("AOV '" + item + "' is not a name:type pair (e.g. dd:depth)");
    Aov a;
    a.name = trim(item.substr(0, colon));
    std::string type = trim(item.substr(colon + 1));
    bool found = false;
    std::vector<std::string> names;
    for (const Named<AovType>& t : kAovTypeNames) {
      names.emplace_back(t.name);
      if (type == t.name) a.type = t.value, found = true;
    }
    if (!found)
      throw std::runtime_error("unknown AOV type '" + type + "'" + didYouMean(type, names) + " (" +
                               nameList(kAovTypeNames) + ")");
    if (a.name.empty()) throw std::runtime_error("AOV '" + item + "' has no name");
    // Two AOVs writing one channel would leave only the later one's values in the file.
    for (const std::string& c : aovChannelNames(a))
      if (!channels.insert(c).second) throw std::runtime_error("AOV channel '" + c + "' is given twice");
    out.push_back(a);
  }
  return out;
}

std::vector<std::string> aovChannelNames(const Aov& aov) {
  std::vector<std::string> suffixes;
  switch (aov.type) {
    case AovType::Albedo: suffixes = {"R", "G", "B"}; break;
    case AovType::Depth: suffixes = {"T"}; break;
    case AovType::Position:
    case AovType::GeoNormal:
    case AovType::ShNormal: suffixes = {"X", "Y", "Z"}; break;
    case AovType::Uv: suffixes = {"U", "V"}; break;
    case AovType::PrimIndex:
    case AovType::ShapeIndex: suffixes = {"I"}; break;
    case AovType::Alpha: return {"A"};
  }
  std::vector<std::string> out;
  for (const std::string& s : suffixes) out.push_back(aov.name + "." + s);
  return out;
}

}  // namespace envgi
