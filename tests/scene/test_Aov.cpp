// Mitsuba's AOV list: name:type pairs, the channels each fills, and clear errors.
#include <gtest/gtest.h>

#include <stdexcept>

#include "scene/Aov.h"

using namespace envgi;

namespace {
std::string parseError(const std::string& spec) {
  try {
    parseAovs(spec);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Aov, ParsesMitsubasListIntoChannels) {
  std::vector<Aov> a = parseAovs("dd.y:depth, nn:sh_normal,alb:albedo,p:position,t:uv,g:geo_normal,i:prim_index,s:shape_index");
  ASSERT_EQ(a.size(), 8u);
  EXPECT_EQ(a[0].name, "dd.y");
  EXPECT_EQ(a[0].type, AovType::Depth);
  EXPECT_EQ(aovChannelNames(a[0]), std::vector<std::string>({"dd.y.T"}));
  EXPECT_EQ(a[1].type, AovType::ShNormal);
  EXPECT_EQ(aovChannelNames(a[1]), std::vector<std::string>({"nn.X", "nn.Y", "nn.Z"}));
  EXPECT_EQ(aovChannelNames(a[2]), std::vector<std::string>({"alb.R", "alb.G", "alb.B"}));
  EXPECT_EQ(aovChannelNames(a[4]), std::vector<std::string>({"t.U", "t.V"}));
  EXPECT_EQ(a[5].type, AovType::GeoNormal);
  EXPECT_EQ(aovChannelNames(a[6]), std::vector<std::string>({"i.I"}));
  EXPECT_EQ(a[7].type, AovType::ShapeIndex);
  EXPECT_TRUE(parseAovs("").empty());
  EXPECT_TRUE(parseAovs(" ").empty());
}

TEST(Aov, RefusesWhatIsNotANameTypeList) {
  EXPECT_NE(parseError("dd").find("not a name:type pair"), std::string::npos);
  EXPECT_NE(parseError(":depth").find("not a name:type pair"), std::string::npos);
  EXPECT_NE(parseError("dd:").find("not a name:type pair"), std::string::npos);
  EXPECT_NE(parseError("a:b:depth").find("not a name:type pair"), std::string::npos);
  EXPECT_NE(parseError("dd:depht").find("unknown AOV type 'depht' (did you mean 'depth'?)"), std::string::npos)
      << parseError("dd:depht");
  EXPECT_NE(parseError("dd:depth,,nn:sh_normal").find("empty entry"), std::string::npos);
  EXPECT_NE(parseError("a:depth,a:depth").find("channel 'a.T' is given twice"), std::string::npos);
  EXPECT_NE(parseError("n:sh_normal,n:geo_normal").find("given twice"), std::string::npos);
  EXPECT_EQ(parseError("a:depth,a:uv"), "") << "a.T and a.U, a.V are different channels";
}
