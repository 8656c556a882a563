// File helpers for outputs that must never be left half-written.
#pragma once

#include <string>

namespace envgi {

// The extension of `path`, lower-cased (".EXR" -> ".exr"): what formats are chosen by.
std::string lowerExtension(const std::string& path);

// A hidden temporary name beside `path` ending in `suffix`, unique to this process.
std::string temporarySibling(const std::string& path, const std::string& suffix);

// Renames a finished temporary file onto `path`; removes it and throws if that fails.
void renameIntoPlace(const std::string& tmp, const std::string& path);

// Throws unless `path` could be written: its directory must exist and take new files. Commands
// call it before long work, so that a mistyped folder does not cost a render its samples.
void requireWritableDirectoryOf(const std::string& path);

// Makes the folders an output at path needs, as `study -o a/b/c` makes its own; throws naming
// the path where one cannot be made (a file in the way, no permission).
void makeParentDirectories(const std::string& path);

// Writes `content` to a hidden temporary file beside `path`, then renames it into place.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace envgi
