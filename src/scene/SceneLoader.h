// Reads scenes in a subset of Mitsuba 3's XML format (docs/scene-format.md).
#pragma once

#include <map>
#include <string>

#include "scene/Scene.h"

namespace envgi {

// Loads and finalises a scene. `defines` override <default> values (-D name=value).
// Errors throw std::runtime_error as "FILE:LINE: what is wrong".
void loadScene(const std::string& path, const std::map<std::string, std::string>& defines, Scene& scene);

}  // namespace envgi
