// File helpers for outputs that must never be left half-written.
#pragma once

#include <string>

namespace envgi {

// A hidden temporary name beside `path` ending in `suffix`, unique to this process.
std::string temporarySibling(const std::string& path, const std::string& suffix);

// Renames a finished temporary file onto `path`; removes it and throws if that fails.
void renameIntoPlace(const std::string& tmp, const std::string& path);

// Writes `content` to a hidden temporary file beside `path`, then renames it into place.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace envgi
