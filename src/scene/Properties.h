// A plugin's named scalar properties as the scene file gave them (parameters substituted),
// parsed by type when a plugin's settings ask for them. Settings structs read themselves from
// it (fromProperties), so the XML loader only collects and dispatches; what no one asked for
// is reported as unused.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace envgi {

// The value parsers, shared with the loader's own properties; they throw without a location.
float parseFloatValue(const std::string& s);
int parseIntValue(const std::string& s);
bool parseBoolValue(const std::string& s);

class Properties {
 public:
  explicit Properties(std::string where = "") : where_(std::move(where)) {}

  // tag: float | integer | boolean | string (others are kept so that reading them says so).
  void set(const std::string& name, const std::string& tag, const std::string& value, const std::string& where = "");

  float getFloat(const std::string& name, float def);
  int getInt(const std::string& name, int def);
  bool getBool(const std::string& name, bool def);
  std::string getString(const std::string& name, const std::string& def);

  // Throws "where: what", at the plugin's element.
  [[noreturn]] void fail(const std::string& what) const;
  // Names never read, with where each was given.
  std::vector<std::pair<std::string, std::string>> unused() const;
  // Every name a reader asked for, given or not (candidates for "did you mean").
  const std::set<std::string>& asked() const { return asked_; }

 private:
  struct Entry {
    std::string tag, value, where;
    bool used = false;
  };
  std::map<std::string, Entry> entries_;
  std::set<std::string> asked_;
  std::string where_;
  const Entry* take(const std::string& name, std::initializer_list<const char*> tags);
};

}  // namespace envgi
