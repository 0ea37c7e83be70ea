// The calibration figure from a calibrated_run record alone: its CSV has the record's rows, its
// script draws the force only when there is one, and the section escapes the force's name and
// never prints "nan".
#include "validate/report/calibrated_figure.hpp"

#include <gtest/gtest.h>

namespace rdyn::validate {
namespace {

using json = nlohmann::json;

json record(bool force) {
  json c = {{"cadence_hz", 0.5},
            {"force_name", force ? "<knee>" : ""},
            {"qdot_error", 2e-5},
            {"force_error", force ? json(1.5e-3) : json(nullptr)},
            {"mean_cadence_full_hz", 0.5000001},
            {"mean_cadence_reduced_hz", nullptr}};
  c["curve"] = {{"names", force ? json{"t", "qdot_full", "qdot_reduced", "force_full_N", "force_reduced_N"}
                                : json{"t", "qdot_full", "qdot_reduced"}},
                {"rows", force ? json{{0.0, 3.1, 3.1, 10.0, 10.5}, {0.5, 3.2, 3.25, 11.0, 11.0}}
                               : json{{0.0, 3.1, 3.1}, {0.5, 3.2, 3.25}}}};
  return c;
}

TEST(CalibratedFigure, CsvScriptAndSectionFromTheRecord) {
  const json c = record(true);
  EXPECT_EQ(calibrated_run_csv(c), "t,qdot_full,qdot_reduced,force_full_N,force_reduced_N\n0,3.1,3.1,10,10.5\n"
                                   "0.5,3.2,3.25,11,11\n");
  const std::string gp = calibrated_run_gp(c);
  EXPECT_NE(gp.find("layout 2,1"), std::string::npos) << gp;
  EXPECT_NE(gp.find("using 1:5"), std::string::npos) << gp;
  const std::string h = calibrated_run_section(c, {{"calibrated", "<?xml?><svg id=c></svg>"}});
  EXPECT_NE(h.find("<svg id=c></svg>"), std::string::npos);
  EXPECT_EQ(h.find("<?xml"), std::string::npos);
  EXPECT_NE(h.find("&lt;knee&gt; 0.15 %"), std::string::npos) << h;
  EXPECT_NE(h.find("reduced n/a Hz"), std::string::npos) << h;
  EXPECT_EQ(h.find("nan"), std::string::npos) << h;
  // No force: one panel, no force words; a missing figure is said.
  const json q = record(false);
  EXPECT_NE(calibrated_run_gp(q).find("layout 1,1"), std::string::npos);
  EXPECT_EQ(calibrated_run_gp(q).find("using 1:4"), std::string::npos);
  EXPECT_NE(calibrated_run_section(q, {}).find("could not be rendered"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
