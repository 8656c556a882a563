// Each integrator's settings read themselves from properties: defaults in one place, errors
// with the property's line, unknown names refused, unread properties reported.
#include <gtest/gtest.h>

#include "integrators/PathIntegrator.h"
#include "integrators/PhotonIntegrator.h"
#include "integrators/Sppm.h"
#include "scene/IntegratorSettings.h"
#include "scene/NameTables.h"
#include "render/PhotonShooter.h"

using namespace envgi;

namespace {
std::string errorOf(IntegratorType t, Properties p) {
  try {
    IntegratorSettings::fromProperties(t, p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Properties, ParsesByTypeAndNamesTheLine) {
  Properties p("s.xml:3");
  p.set("a", "integer", "7", "s.xml:4");
  p.set("b", "float", "0.5", "s.xml:5");
  p.set("c", "boolean", "true", "s.xml:6");
  p.set("d", "string", "mis", "s.xml:7");
  p.set("e", "integer", "7.5", "s.xml:8");
  p.set("f", "string", "x", "s.xml:9");
  EXPECT_EQ(p.getInt("a", 0), 7);
  EXPECT_FLOAT_EQ(p.getFloat("a", 0.f), 7.f) << "an integer is a float too";
  EXPECT_FLOAT_EQ(p.getFloat("b", 0.f), 0.5f);
  EXPECT_TRUE(p.getBool("c", false));
  EXPECT_EQ(p.getString("d", ""), "mis");
  EXPECT_EQ(p.getInt("absent", 42), 42);
  try {
    p.getInt("e", 0);
    FAIL() << "7.5 read as an integer";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "s.xml:8: '7.5' is not an integer");
  }
  try {
    p.getInt("f", 0);
    FAIL() << "a string read as an integer";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "s.xml:9: property 'f' cannot be a <string>");
  }
  p.set("g", "float", "1", "s.xml:10");
  auto unused = p.unused();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0].first, "g");
  EXPECT_EQ(unused[0].second, "s.xml:10");
}

// The kernels' parameter structs start from the same defaults as the settings the scene file
// fills, so a test or tool that builds one directly renders what a bare scene file would.
TEST(IntegratorSettings, KernelDefaultsAgreeWithSettings) {
  Properties none("s.xml:1");
  IntegratorSettings path = IntegratorSettings::fromProperties(IntegratorType::Path, none);
  EXPECT_EQ(path.path.maxDepth, PathParams{}.maxDepth);
  EXPECT_EQ(path.path.rrDepth, PathParams{}.rrDepth);
  EXPECT_EQ(path.env.strategy, "product");
  EXPECT_EQ(findStrategy(path.env.strategy).env, PathParams{}.envStrategy);
  IntegratorSettings photon = IntegratorSettings::fromProperties(IntegratorType::Photon, none);
  EXPECT_EQ(photon.photon.gatherSamples, PhotonRenderParams{}.gatherSamples);
  EXPECT_EQ(photon.photon.maxDepth, PhotonRenderParams{}.chain.maxDepth);
  EXPECT_EQ(photon.photon.maxDepth, PhotonShootSettings{}.maxDepth);
  EXPECT_EQ(photon.photon.rrDepth, PhotonRenderParams{}.chain.rrDepth);
  IntegratorSettings sppm = IntegratorSettings::fromProperties(IntegratorType::Sppm, none);
  EXPECT_EQ(sppm.sppm.maxDepth, SppmParams{}.maxDepth);
  EXPECT_EQ(sppm.sppm.photonCount, SppmParams{}.photonsPerPass);
  EXPECT_FLOAT_EQ(sppm.sppm.alpha, SppmParams{}.alpha);
  EXPECT_FLOAT_EQ(photon.photon.causticRadius(2.f), 0.25f * photon.photon.globalRadius(2.f));
  EXPECT_FLOAT_EQ(photon.photon.globalRadius(2.f), 0.1f);
}

TEST(IntegratorSettings, ReadsEachIntegratorsOwnProperties) {
  Properties p("s.xml:1");
  p.set("max_depth", "integer", "3");
  p.set("rr_depth", "integer", "2");
  p.set("strategy", "string", "adaptive");
  p.set("passes", "integer", "9");  // an sppm property: unread by path
  IntegratorSettings s = IntegratorSettings::fromProperties(IntegratorType::Path, p);
  EXPECT_EQ(s.path.maxDepth, 3);
  EXPECT_EQ(s.path.rrDepth, 2);
  EXPECT_EQ(s.env.strategy, "adaptive");
  EXPECT_EQ(s.sppm.passes, SppmSettings{}.passes);
  auto unused = p.unused();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0].first, "passes");

  Properties d("s.xml:1");
  d.set("shading_samples", "integer", "4");
  d.set("bsdf_samples", "integer", "0");
  s = IntegratorSettings::fromProperties(IntegratorType::Direct, d);
  EXPECT_EQ(s.direct.emitterSamples, 4);
  EXPECT_EQ(s.direct.bsdfSamples, 0);
}

// max_depth -1 is Mitsuba's "unbounded": path keeps it; the photon integrators, whose loops run
// to a depth, read it as kUnboundedChainDepth (it had ended every chain at once).
TEST(IntegratorSettings, MaxDepthMinusOneIsUnboundedForEveryIntegrator) {
  Properties p("s.xml:1");
  p.set("max_depth", "integer", "-1");
  EXPECT_EQ(IntegratorSettings::fromProperties(IntegratorType::Path, p).path.maxDepth, -1);
  EXPECT_EQ(IntegratorSettings::fromProperties(IntegratorType::Photon, p).photon.maxDepth, kUnboundedChainDepth);
  EXPECT_EQ(IntegratorSettings::fromProperties(IntegratorType::Sppm, p).sppm.maxDepth, kUnboundedChainDepth);
  EXPECT_EQ(IntegratorSettings::fromProperties(IntegratorType::Grid, p).grid.maxDepth, kUnboundedChainDepth);
  EXPECT_GT(kUnboundedChainDepth, kSpecularChainDepth);
}

TEST(IntegratorSettings, RefusesBadValuesAtThePluginsLine) {
  auto with = [](const char* name, const char* tag, const char* value) {
    Properties p("s.xml:2");
    p.set(name, tag, value);
    return p;
  };
  EXPECT_EQ(errorOf(IntegratorType::Path, with("strategy", "string", "nope")),
            "s.xml:2: unknown strategy 'nope' (" + strategyNameList() + ")");
  EXPECT_EQ(errorOf(IntegratorType::Path, with("max_depth", "integer", "0")),
            "s.xml:2: max_depth must be -1 or at least 1");
  EXPECT_EQ(errorOf(IntegratorType::Photon, with("lookup_size", "integer", "513")),
            "s.xml:2: lookup_size must be between 1 and 512");
  EXPECT_EQ(errorOf(IntegratorType::Sppm, with("alpha", "float", "1")), "s.xml:2: alpha must be in (0, 1)");
  EXPECT_EQ(errorOf(IntegratorType::Direct, with("emitter_samples", "integer", "-2")),
            "s.xml:2: sample counts must not be negative");
  EXPECT_EQ(errorOf(IntegratorType::Grid, with("gather_rays", "integer", "0")), "s.xml:2: gather_rays must be positive");
  EXPECT_EQ(errorOf(IntegratorType::Grid, with("refine_rays", "integer", "-1")),
            "s.xml:2: refine_rays must not be negative");
  EXPECT_EQ(errorOf(IntegratorType::Grid, with("max_gather_rays", "integer", "64")),
            "s.xml:2: max_gather_rays must be at least gather_rays");
  EXPECT_EQ(errorOf(IntegratorType::Path, with("point_method", "string", "kmeans")),
            "s.xml:2: unknown point_method 'kmeans' (sample, mediancut)");
  // Two billion lights had reached the collapse, whose allocation the system refused.
  EXPECT_EQ(errorOf(IntegratorType::Direct, with("point_count", "integer", "2000000000")),
            "s.xml:2: point_count must be between 1 and 16777216");
}

TEST(IntegratorSettings, SetStrategyResetsDirectsCountsToTheStrategys) {
  IntegratorSettings s;
  s.direct.emitterSamples = 5;
  s.direct.bsdfSamples = 0;
  s.setStrategy("bsdf");
  EXPECT_EQ(s.env.strategy, "bsdf");
  EXPECT_EQ(s.direct.emitterSamples, -1);
  EXPECT_EQ(s.direct.bsdfSamples, -1);
  EXPECT_THROW(s.setStrategy("nope"), std::runtime_error);
}

// The study's names carry the collapsed map's size; the same names work wherever a strategy is set.
TEST(IntegratorSettings, CollapsedMapStrategiesMayCarryTheirSize) {
  IntegratorSettings s;
  s.setStrategy("points-256");
  EXPECT_EQ(s.env.strategy, "points");
  EXPECT_EQ(s.env.pointCount, 256);
  s.setStrategy("points-draw-8");
  EXPECT_EQ(s.env.strategy, "points-draw");
  EXPECT_EQ(s.env.pointCount, 8);
  s.setStrategy("points");  // the size the scene set stays
  EXPECT_EQ(s.env.pointCount, 8);
  for (const char* bad : {"points-0", "points-", "points-12x", "points-draw-99999999999", "points--3", "points-draw-"})
    EXPECT_THROW(s.setStrategy(bad), std::runtime_error) << bad;
  EXPECT_EQ(s.env.strategy, "points");
}

// Every listed name finds its value and back; aliases find theirs but are not listed.
TEST(NameTables, NamesRoundTripAndUnknownNamesAreErrors) {
  for (const auto& n : kIntegratorNames) {
    EXPECT_EQ(findIntegrator(n.name), n.value);
    if (!n.alias) {
      EXPECT_STREQ(integratorName(n.value), n.name);
    }
  }
  for (const auto& n : kSamplerNames) {
    EXPECT_EQ(findSampler(n.name), n.value);
    if (!n.alias) {
      EXPECT_STREQ(samplerName(n.value), n.name);
    }
  }
  for (const auto& n : kFilterNames) EXPECT_EQ(findName(kFilterNames, n.name, "rfilter type"), n.value);
  for (const auto& n : kStrategyNames) EXPECT_STREQ(findStrategy(n.name).name, n.name);
  EXPECT_EQ(nameList(kIntegratorNames), "path, direct, photon, sppm, grid");
  EXPECT_EQ(nameList(kSamplerNames), "independent, stratified, sobol");
  EXPECT_EQ(findIntegrator("photonmapper"), IntegratorType::Photon);
  EXPECT_EQ(findIntegrator("volpath"), IntegratorType::Path);
  EXPECT_EQ(findIntegrator("volpathmis"), IntegratorType::Path);
  EXPECT_EQ(findSampler("ldsampler"), SamplerType::Sobol);
  try {
    findSampler("halton");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "unknown sampler 'halton' (independent, stratified, sobol)");
  }
  EXPECT_THROW(findIntegrator("bdpt"), std::runtime_error);
  EXPECT_THROW(findStrategy("uniform-ish"), std::runtime_error);
  EXPECT_THROW(findStrategy("mis", /*mapOnly=*/true), std::runtime_error);
}

// The grid's basis and its count of directions: named values and a bounded count only.
TEST(IntegratorSettings, GridBasisAndDirectionsAreChecked) {
  auto gridWith = [](const std::string& name, const std::string& tag, const std::string& value) {
    Properties p;
    p.set(name, tag, value);
    return GridSettings::fromProperties(p);
  };
  EXPECT_EQ(gridWith("basis", "string", "directions").basis, "directions");
  EXPECT_EQ(gridWith("directions", "integer", "256").directions, 256);
  EXPECT_THROW(gridWith("basis", "string", "wavelets"), std::runtime_error);
  EXPECT_THROW(gridWith("directions", "integer", "0"), std::runtime_error);
  EXPECT_THROW(gridWith("directions", "integer", "5000"), std::runtime_error);
}
