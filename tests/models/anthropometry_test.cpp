// de Leva (1996) segment fractions (models/anthropometry.cpp): the fractions give back the
// published Table 4 lengths at the reference statures, the mass fractions are the published
// ones, another sex is refused, and the bicycle-leg generator's thigh is fraction × stature.
#include "models/anthropometry.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <utility>

#include "models/bicycle_leg.hpp"

namespace rdyn::models {
namespace {

// de Leva P. (1996), J. Biomech. 29(9):1223–1230, Table 4, typed here from the paper: segment
// lengths [mm] of the reference subjects, stature 1741 mm (male) and 1735 mm (female).
struct Table4Row {
  const char* sex;
  double stature_mm;
  double thigh_mm, shank_mm, foot_mm;
  double thigh_mass, shank_mass, foot_mass;  // % of body mass
};
constexpr Table4Row kTable4[] = {
    {"male", 1741.0, 422.2, 434.0, 258.1, 14.16, 4.33, 1.37},
    {"female", 1735.0, 369.8, 432.3, 228.3, 14.78, 4.81, 1.29},
};

TEST(Anthropometry, FractionsGiveBackTable4LengthsAtTheReferenceStatures) {
  for (const auto& row : kTable4) {
    const LowerLimbFractions f = de_leva_1996(row.sex);
    // Lengths rounded to 0.1 mm in the table: the fraction × stature must give them to rounding.
    EXPECT_NEAR(f.thigh.length * row.stature_mm, row.thigh_mm, 1e-9) << row.sex;
    EXPECT_NEAR(f.shank.length * row.stature_mm, row.shank_mm, 1e-9) << row.sex;
    EXPECT_NEAR(f.foot.length * row.stature_mm, row.foot_mm, 1e-9) << row.sex;
    // Fractions of stature are physical: a thigh is about a quarter of the height.
    EXPECT_GT(f.thigh.length, 0.2) << row.sex;
    EXPECT_LT(f.thigh.length, 0.26) << row.sex;
  }
}

TEST(Anthropometry, MassFractionsAsPublished) {
  for (const auto& row : kTable4) {
    const LowerLimbFractions f = de_leva_1996(row.sex);
    EXPECT_NEAR(100 * f.thigh.mass, row.thigh_mass, 1e-12) << row.sex;
    EXPECT_NEAR(100 * f.shank.mass, row.shank_mass, 1e-12) << row.sex;
    EXPECT_NEAR(100 * f.foot.mass, row.foot_mass, 1e-12) << row.sex;
  }
  // Table 4's thigh CoM positions (from the hip): 40.95 % (male), 36.12 % (female).
  EXPECT_NEAR(de_leva_1996("male").thigh.com, 0.4095, 1e-12);
  EXPECT_NEAR(de_leva_1996("female").thigh.com, 0.3612, 1e-12);
  // Ankle height: Drillis & Contini (1966), 0.039 of stature for both.
  EXPECT_EQ(de_leva_1996("male").ankle_height, 0.039);
  EXPECT_EQ(de_leva_1996("female").ankle_height, 0.039);
}

TEST(Anthropometry, AnotherSexIsRefused) {
  for (const std::string sex : {"", "Male", "m", "other", "male "}) {
    try {
      de_leva_1996(sex);
      ADD_FAILURE() << "'" << sex << "' accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'male' or 'female'"), std::string::npos) << e.what();
    }
  }
}

// Two routes to a thigh length: the generator's thigh (hip → knee point) for a subject who is
// not de Leva's reference, and the table's fraction times the height given.
TEST(Anthropometry, GeneratedThighIsTheFractionOfTheHeightGiven) {
  for (const auto& [sex, height_m] : {std::pair<std::string, double>{"female", 1.62}, {"male", 1.93}}) {
    BicycleLegParams p;
    p.sex = sex;
    p.height_m = height_m;
    p.mass_kg = 68.0;
    Scene s;
    s.name = "leg";
    make_bicycle_leg(p, s);
    const Body* thigh = s.find_body("thigh_r");
    ASSERT_NE(thigh, nullptr);
    const double expected = de_leva_1996(sex).thigh.length * height_m;
    EXPECT_NEAR(thigh->points.at("knee").x - thigh->points.at("hip").x, expected, 1e-12) << sex;
    EXPECT_NEAR(thigh->mass_kg, de_leva_1996(sex).thigh.mass * 68.0, 1e-12) << sex;
  }
}

}  // namespace
}  // namespace rdyn::models
