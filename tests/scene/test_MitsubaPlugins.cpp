#include "scene/MitsubaPlugins.h"

#include <gtest/gtest.h>

using namespace envgi;

// A plugin takes its own parameters and its base class's, and no other type's.
TEST(MitsubaPlugins, PluginsTakeTheirOwnAndTheirBaseClassesProperties) {
  EXPECT_TRUE(mitsubaPluginTakes("shape", "sphere", "radius"));
  EXPECT_TRUE(mitsubaPluginTakes("shape", "sphere", "to_world")) << "Shape's";
  EXPECT_TRUE(mitsubaPluginTakes("shape", "ply", "face_normals")) << "Mesh's";
  EXPECT_FALSE(mitsubaPluginTakes("shape", "rectangle", "radius"));
  EXPECT_FALSE(mitsubaPluginTakes("shape", "ply", "radius"));
  EXPECT_TRUE(mitsubaPluginTakes("sensor", "thinlens", "aperture_radius"));
  EXPECT_FALSE(mitsubaPluginTakes("sensor", "perspective", "aperture_radius"));
  EXPECT_TRUE(mitsubaPluginTakes("integrator", "path", "samples_per_pass")) << "Integrator's";
  EXPECT_TRUE(mitsubaPluginTakes("integrator", "direct", "bsdf_samples"));
  EXPECT_FALSE(mitsubaPluginTakes("integrator", "path", "bsdf_samples"));
  EXPECT_TRUE(mitsubaPluginTakes("bsdf", "roughconductor", "alpha_v"));
  EXPECT_FALSE(mitsubaPluginTakes("bsdf", "roughplastic", "alpha_v")) << "Mitsuba's rough plastic is isotropic";
  EXPECT_FALSE(mitsubaPluginTakes("emitter", "constant", "scale"));
  EXPECT_TRUE(mitsubaPluginTakes("emitter", "envmap", "scale"));
  EXPECT_FALSE(mitsubaPluginTakes("bsdf", "sphere", "radius")) << "the kind counts, not only the type";
}

TEST(MitsubaPlugins, NearestNameIsAtMostTwoEditsAwayAndNeverTheNameItself) {
  const std::vector<std::string> names = {"radius", "to_world", "flip_normals", "alpha", "alpha_u"};
  EXPECT_EQ(nearestName("radus", names), "radius");       // a deletion
  EXPECT_EQ(nearestName("raduis", names), "radius");      // a swap: two edits
  EXPECT_EQ(nearestName("to_wrld", names), "to_world");
  EXPECT_EQ(nearestName("alpha_v", names), "alpha_u") << "the nearest wins";
  EXPECT_EQ(nearestName("alpha_u", names), "alpha") << "a name never suggests itself";
  EXPECT_EQ(nearestName("mystery", names), "");
  EXPECT_EQ(nearestName("ab", {"a", "b"}), "") << "one edit is half of a two-letter name";
  EXPECT_EQ(nearestName("sp", {"spp", "res"}), "spp") << "one edit of three letters";
  EXPECT_EQ(nearestName("x", {}), "");
}

// The hint the loader's errors and warnings end with, in one form for each.
TEST(MitsubaPlugins, DidYouMeanQuotesTheNearestName) {
  const std::vector<std::string> names = {"radius", "center", "to_world"};
  EXPECT_EQ(didYouMean("radus", names), " (did you mean 'radius'?)");
  EXPECT_EQ(didYouMean("shap", {"shape", "bsdf"}, "<", ">"), " (did you mean <shape>?)");
  EXPECT_EQ(didYouMean("velvet", names), "");
}
