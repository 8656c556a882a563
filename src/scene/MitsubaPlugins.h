// The property names Mitsuba 3's plugins take: each plugin's documented parameters and those of
// its base classes (Shape, Mesh, Emitter, Sensor, Film, Sampler, Integrator). The loader tells
// with it a property envgi leaves out, which a Mitsuba scene may set (a warning), from one that no
// Mitsuba plugin of that type has, such as a misspelt name, which Mitsuba refuses ("Unreferenced
// property") and envgi then refuses too, rather than render without it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace envgi {

// kind: the element (bsdf, emitter, film, integrator, rfilter, sampler, sensor, shape, texture).
bool mitsubaPluginTakes(std::string_view kind, std::string_view type, std::string_view name);

// Of the candidates other than name itself, the one nearest to it by edit distance, if it is at
// most 2 edits away and fewer than half the longer name's letters; empty otherwise ("did you
// mean ...?").
std::string nearestName(std::string_view name, const std::vector<std::string>& candidates);
// The hint an error or warning ends with: " (did you mean 'radius'?)" for the nearest name,
// quoted between `open` and `close` (<bsdf> for elements); empty when none is near.
std::string didYouMean(std::string_view name, const std::vector<std::string>& candidates, std::string_view open = "'",
                       std::string_view close = "'");

// The names mitsubaPluginTakes accepts for one plugin, for nearestName.
std::vector<std::string> mitsubaPluginProperties(std::string_view kind, std::string_view type);

}  // namespace envgi
