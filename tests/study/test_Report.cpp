#include <gtest/gtest.h>

#include "study/ErrorMetrics.h"
#include "study/Report.h"

using namespace envgi;

TEST(StudyReport, ErrorMetricsOnKnownImages) {
  Image a(2, 1), r(2, 1);
  a.set(0, 0, Color(1.f));
  r.set(0, 0, Color(0.f));
  ImageError e = imageError(a, r);
  EXPECT_NEAR(e.rmse, std::sqrt(3.0 / 6.0), 1e-9);
  EXPECT_NEAR(e.relMse, 3.0 / 0.01 / 6.0, 1e-6);
  EXPECT_EQ(imageError(r, r).rmse, 0.0);
  // All the error in one pixel of a 4x4 image: the worst region holds it alone.
  Image b(4, 4), z(4, 4);
  b.set(3, 0, Color(2.f));
  ImageError eb = imageError(b, z);
  EXPECT_NEAR(eb.rmse, std::sqrt(12.0 / 48.0), 1e-9);
  EXPECT_NEAR(eb.worstRegionRmse, 2.0, 1e-9);
  EXPECT_THROW(imageError(Image(3, 1), r), std::runtime_error);
}

TEST(StudyReport, Base64AndSvg) {
  EXPECT_EQ(base64("Man"), "TWFu");
  EXPECT_EQ(base64("Ma"), "TWE=");
  EXPECT_EQ(base64("M"), "TQ==");
  std::string svg = svgLogLogPlot("t", "x", "y", {"a", "b"}, {{1, 4, 16}, {1, 4}}, {{1, 0.5, 0.25}, {0.3, 0.2}});
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  size_t lines = 0;
  for (size_t p = svg.find("<polyline"); p != std::string::npos; p = svg.find("<polyline", p + 1)) ++lines;
  EXPECT_EQ(lines, 2u);
  EXPECT_NE(svg.find(">a<"), std::string::npos);
}

namespace {
// The stroke colour of the polyline of the series drawn `index`-th.
std::string strokeOf(const std::string& svg, int index) {
  size_t p = svg.find("<polyline");
  for (int i = 0; i < index; ++i) p = svg.find("<polyline", p + 1);
  const size_t s = svg.find("stroke=\"", p) + 8;
  return svg.substr(s, svg.find('"', s) - s);
}
}  // namespace

// A strategy keeps its colour from one report to the next, whatever else the report holds
// (it once took the colour of its place in the list); the collapsed map's sizes differ.
TEST(StudyReport, AStrategyKeepsItsColourAcrossReports) {
  const std::string one = svgLogLogPlot("t", "x", "y", {"uniform", "product"}, {{1, 4}, {1, 4}}, {{1, 0.5}, {1, 0.4}});
  const std::string two = svgLogLogPlot("t", "x", "y", {"product"}, {{1, 4}}, {{1, 0.4}});
  EXPECT_EQ(strokeOf(one, 1), strokeOf(two, 0));
  EXPECT_NE(strokeOf(one, 0), strokeOf(one, 1));
  const std::string points =
      svgLogLogPlot("t", "x", "y", {"points-16", "points-256", "points-draw-16"}, {{1}, {1}, {1}}, {{1}, {1}, {1}});
  EXPECT_NE(strokeOf(points, 0), strokeOf(points, 1));
  EXPECT_NE(strokeOf(points, 0), strokeOf(points, 2));
}

// The error maps come with their colour bar.
TEST(StudyReport, TheErrorMapsHaveAColourBar) {
  Image ref(4, 4), img(4, 4);
  for (float& v : ref.rgb) v = 0.5f;
  const std::string html = studyReportHtml("scene.xml", {{"uniform", 1, 0.0, 0, 0.1, 0.2, 0.3, 0.4}}, ref,
                                           {{"uniform", 1, img}}, {"uniform"});
  const size_t heading = html.find("Relative error");
  ASSERT_NE(heading, std::string::npos);
  const size_t bar = html.find("linearGradient id=\"errorRamp\"", heading);
  ASSERT_NE(bar, std::string::npos);
  EXPECT_LT(bar, html.find("<img", heading)) << "the bar comes before the maps";
  EXPECT_NE(html.find("1 or more", bar), std::string::npos);
}

// With two or more points-N strategies the report plots RMSE against N for each budget and
// says, per budget, which collapsed map is best and what it beats and loses to.
TEST(StudyReport, TheCollapsedMapSectionStatesTheCrossover) {
  std::vector<StudyRun> runs = {
      {"importance", 1, 0.0, 0, 0.01, 0.13}, {"product", 1, 0.0, 0, 0.01, 0.06},
      {"points-16", 1, 0.0, 0, 0.01, 0.04},  {"points-256", 1, 0.0, 0, 0.05, 0.03},
      {"importance", 100, 0.5, 0, 0.5, 0.0075}, {"product", 90, 0.5, 0, 0.5, 0.0036},
      {"points-16", 50, 0.5, 0, 0.5, 0.019},    {"points-256", 11, 0.5, 0, 0.5, 0.0053}};
  Image ref(4, 4);
  std::string html = studyReportHtml("s.xml", runs, ref, {}, {"importance", "product", "points-16", "points-256"});
  EXPECT_NE(html.find("RMSE against the collapsed map's N"), std::string::npos);
  EXPECT_NE(html.find("<li>1 spp: the best collapsed map is points-256 (RMSE 0.03000); it beats importance (0.13000), "
                      "product (0.06000).</li>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<li>0.5 s: the best collapsed map is points-256 (RMSE 0.00530); it beats importance (0.00750); "
                      "it loses to product (0.00360).</li>"),
            std::string::npos);
  // One collapsed map alone: no section.
  std::string one = studyReportHtml("s.xml", runs, ref, {}, {"importance", "points-16"});
  EXPECT_EQ(one.find("RMSE against the collapsed map's N"), std::string::npos);
}
