// Reads scenes in a subset of Mitsuba 3's XML format (docs/scene-format.md).
#pragma once

#include <map>
#include <string>

#include "scene/Scene.h"

namespace envgi {

// Loads and finalises a scene. `defines` override <default> values (-D name=value).
// Errors throw std::runtime_error as "FILE:LINE: what is wrong".
void loadScene(const std::string& path, const std::map<std::string, std::string>& defines, Scene& scene);

// The same from XML text (Mitsuba's load_string): errors say "<string>:LINE: ...", and
// relative file names are taken from the working folder.
inline constexpr const char* kSceneStringName = "<string>";
void loadSceneString(const std::string& xml, const std::map<std::string, std::string>& defines, Scene& scene);

}  // namespace envgi
