#include "scene/Properties.h"

#include <cctype>
#include <cmath>
#include <stdexcept>

namespace envgi {

float parseFloatValue(const std::string& s) {
  try {
    size_t used = 0;
    float v = std::stof(s, &used);
    while (used < s.size() && std::isspace((unsigned char)s[used])) ++used;
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error("'" + s + "' is not a number");
}

int parseIntValue(const std::string& s) {
  try {
    size_t used = 0;
    long v = std::stol(s, &used);
    if (used == s.size() && v >= INT32_MIN && v <= INT32_MAX) return int(v);
  } catch (const std::exception&) {
  }
  throw std::runtime_error("'" + s + "' is not an integer");
}

bool parseBoolValue(const std::string& s) {
  if (s == "true" || s == "1") return true;
  if (s == "false" || s == "0") return false;
  throw std::runtime_error("'" + s + "' is not a boolean");
}

void Properties::set(const std::string& name, const std::string& tag, const std::string& value,
                     const std::string& where) {
  entries_[name] = Entry{tag, value, where.empty() ? where_ : where, false};
}

const Properties::Entry* Properties::take(const std::string& name, std::initializer_list<const char*> tags) {
  asked_.insert(name);
  auto it = entries_.find(name);
  if (it == entries_.end()) return nullptr;
  Entry& e = it->second;
  e.used = true;
  for (const char* t : tags)
    if (e.tag == t) return &e;
  throw std::runtime_error(e.where + ": property '" + name + "' cannot be a <" + e.tag + ">");
}

// Parse errors carry the property's own line.
template <class F>
static auto parseAt(const std::string& where, F&& parse) {
  try {
    return parse();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
}

float Properties::getFloat(const std::string& name, float def) {
  const Entry* e = take(name, {"float", "integer"});
  return e ? parseAt(e->where, [&] { return parseFloatValue(e->value); }) : def;
}

int Properties::getInt(const std::string& name, int def) {
  const Entry* e = take(name, {"integer"});
  return e ? parseAt(e->where, [&] { return parseIntValue(e->value); }) : def;
}

bool Properties::getBool(const std::string& name, bool def) {
  const Entry* e = take(name, {"boolean"});
  return e ? parseAt(e->where, [&] { return parseBoolValue(e->value); }) : def;
}

std::string Properties::getString(const std::string& name, const std::string& def) {
  const Entry* e = take(name, {"string"});
  return e ? e->value : def;
}

void Properties::fail(const std::string& what) const { throw std::runtime_error(where_ + ": " + what); }

std::vector<std::pair<std::string, std::string>> Properties::unused() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, e] : entries_)
    if (!e.used) out.push_back({name, e.where});
  return out;
}

}  // namespace envgi
