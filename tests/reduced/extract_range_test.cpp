// Range tables (issue #10) on the analytic mechanism: a non-periodic grid over [q_min, q_max],
// closed-form samples, the integral of 2·m2 from q_min, switch angles inside the range, the
// not-a-knot interpolant against the periodic one, and the reduced model stopping at the edge.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <gsl/gsl_spline.h>

#include "analytic_source.hpp"
#include "models/scene.hpp"
#include "reduced/extract.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "reduced/table.hpp"

namespace rdyn::reduced {
namespace {

constexpr double kDeg = M_PI / 180;

// Declared limits: the grid rules without the dead-point refinement (tested apart below).
Samples range_samples(test::AnalyticSource& src, const models::Scene& scene, double lo, double hi, double deg,
                      Method method = Method::Kinetostatic, const std::string& min_edge = "declared limit") {
  ExtractOptions opt;
  opt.step_rad = deg * kDeg;
  opt.method = method;
  opt.range = ExtractRange{lo, hi, min_edge, "declared limit"};
  return extract_samples(src, scene, opt);
}

TEST(ExtractRange, GridRules) {
  // Never fewer intervals than a full turn at the same grid (360/g); a revolute range wider
  // than a turn's worth keeps intervals no longer than the step.
  EXPECT_EQ(range_intervals(120 * kDeg, 10 * kDeg, true, false), 36);
  EXPECT_EQ(range_intervals(125 * kDeg, 1 * kDeg, true, false), 360);
  EXPECT_EQ(range_intervals(500 * kDeg, 10 * kDeg, true, false), 50);
  EXPECT_EQ(range_intervals(0.1, 10 * kDeg, false, false), 36);
  EXPECT_EQ(range_intervals(0.1, 2 * kDeg, false, false), 180);
  EXPECT_EQ(range_intervals(20 * kDeg, 10 * kDeg, true, false), 36);
  EXPECT_EQ(range_intervals(20 * kDeg, 90 * kDeg, true, false), 4);  // never fewer than 4 (5 points: Akima's minimum)
  EXPECT_THROW(range_intervals(0.0, 10 * kDeg, true, false), TableError);
  EXPECT_THROW(range_intervals(NAN, 10 * kDeg, true, false), TableError);
  EXPECT_THROW(range_intervals(1e3, 0.01 * kDeg, true, false), TableError);  // > kMaxTableRows points
  // A range ending at a dead point: kDeadPointRefinement× the intervals at every grid (so the
  // ladder's halvings stay halvings), capped at the reader's limit instead of refused.
  EXPECT_EQ(range_intervals(0.1, 10 * kDeg, false, true), 36 * kDeadPointRefinement);
  EXPECT_EQ(range_intervals(0.1, 5 * kDeg, false, true), 72 * kDeadPointRefinement);
  EXPECT_EQ(range_intervals(48 * kDeg, 10 * kDeg, true, true), 36 * kDeadPointRefinement);
  EXPECT_EQ(range_intervals(0.1, 0.01 * kDeg, false, true), kMaxTableRows - 1);
  EXPECT_EQ(range_intervals(0.1, 0.01 * kDeg, false, false), 36000);
}

TEST(ExtractRange, SamplesTheRangeWithClosedFormValuesAndNoWrap) {
  test::AnalyticSource src;
  src.k = 2.0;
  const auto scene = test::analytic_scene();
  const Samples s = range_samples(src, scene, 0.3, 2.5, 10);
  EXPECT_FALSE(s.periodic);
  EXPECT_TRUE(s.revolute);
  ASSERT_EQ(s.q.size(), 37u);  // 2.2 rad = 126°: 36 intervals (a full turn's count at 10°)
  EXPECT_DOUBLE_EQ(s.q.front(), 0.3);
  EXPECT_DOUBLE_EQ(s.q.back(), 2.5);
  EXPECT_NEAR(s.step, 2.2 / 36, 1e-15);
  EXPECT_EQ(s.min_edge, "declared limit");
  EXPECT_EQ(s.max_edge, "declared limit");
  // One edge a dead point: kDeadPointRefinement × the intervals, the edges recorded.
  const Samples fine = range_samples(src, scene, 0.3, 2.5, 10, Method::Kinetostatic, "dead point");
  ASSERT_EQ(fine.q.size(), 36u * kDeadPointRefinement + 1);
  EXPECT_NEAR(fine.step, 2.2 / (36 * kDeadPointRefinement), 1e-15);
  EXPECT_DOUBLE_EQ(fine.q.back(), 2.5);
  EXPECT_EQ(fine.min_edge, "dead point");
  EXPECT_EQ(fine.max_edge, "declared limit");
  for (size_t i = 0; i < s.q.size(); ++i) {
    EXPECT_NEAR(s.columns[s.require("m1")][i], src.sc.m1(s.q[i]), 1e-14);
    EXPECT_NEAR(s.columns[s.require("Q_cons")][i], -2.0 * std::sin(s.q[i]), 1e-14);
  }
}

TEST(ExtractRange, EveryInterpolationBuildsOnTheCoarsestRangeTable) {
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  const Samples s = range_samples(src, scene, 0.3, 0.6, 90);  // 4 intervals, 5 points
  ASSERT_EQ(s.q.size(), 5u);
  for (auto i : {Interpolation::CubicSpline, Interpolation::Akima, Interpolation::Linear, Interpolation::Fourier})
    EXPECT_NO_THROW(build_table(s, i)) << interpolation_name(i);
  Samples four = s;  // hand-made, below the reader's minimum for Akima
  four.q.pop_back();
  for (auto& c : four.columns) c.pop_back();
  EXPECT_THROW(build_table(four, Interpolation::Akima), TableError);
}

// A source whose sample at one q is flagged singular and carries garbage (as a configuration
// where the loop Jacobian lost rank would).
class SingularAt : public test::AnalyticSource {
 public:
  double q_bad = 0.0;
  GridSample sample(double q, bool with_conservative) override {
    GridSample g = KinetostaticSource::sample(q, with_conservative);
    if (std::abs(q - q_bad) < 1e-12) {
      g.singular = true;
      g.acceleration.driving_force = 1e6;  // m1
    }
    return g;
  }
};

TEST(ExtractRange, ASingularSampleInsideTheRangeIsRepairedWithoutWrapping) {
  SingularAt src;
  const auto scene = test::analytic_scene();
  const Samples clean = range_samples(src, scene, 0.3, 2.5, 5);
  src.q_bad = clean.q[10];
  const Samples s = range_samples(src, scene, 0.3, 2.5, 5);
  ASSERT_EQ(s.singular_q.size(), 1u);
  EXPECT_EQ(s.singular_q[0], clean.q[10]);
  // Replaced by the spline through the regular samples: close to the closed form, far from 1e6.
  EXPECT_NEAR(s.columns[s.require("m1")][10], src.sc.m1(clean.q[10]), 1e-4 * src.sc.m1(clean.q[10]));
  for (size_t i = 0; i < s.q.size(); ++i)
    if (i != 10) {
      EXPECT_EQ(s.columns[s.require("m1")][i], clean.columns[clean.require("m1")][i]);
    }
  // At the range's very edge there is nothing to interpolate from on one side: refused.
  src.q_bad = clean.q.back();
  EXPECT_THROW(range_samples(src, scene, 0.3, 2.5, 5), models::NumericalError);
}

TEST(ExtractRange, PrismaticNeedsARange) {
  test::AnalyticSource src;
  auto scene = test::analytic_scene();
  scene.joints[0].type = models::JointType::Prismatic;
  ExtractOptions opt;
  EXPECT_THROW(extract_samples(src, scene, opt), TableError);
  opt.range = ExtractRange{0.3, 1.3, "", ""};
  const Samples s = extract_samples(src, scene, opt);
  EXPECT_FALSE(s.revolute);
  EXPECT_EQ(s.q.size(), 37u);  // 10° grid: 36 intervals over the stroke
}

TEST(ExtractRange, IntegratedM1StartsAtTheRangeMinimumAndConverges) {
  // m1 = m1(q_min) + ∫ from q_min of 2 m2 (not-a-knot spline of m2): error falls like h⁴.
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  double previous = INFINITY;
  for (double deg : {10.0, 5.0, 2.5}) {
    const Samples s = range_samples(src, scene, 0.3, 2.5, deg, Method::Integrated);
    EXPECT_EQ(s.columns[0][0], src.sc.m1(0.3));
    double err = 0;
    for (size_t i = 0; i < s.q.size(); ++i) err = std::max(err, std::abs(s.columns[0][i] - src.sc.m1(s.q[i])));
    EXPECT_LT(err, previous / 8) << deg;  // h⁴: 16× per halving
    if (deg == 5.0) {
      EXPECT_LT(err / src.sc.m1(0.3), 1e-4);
    }
    previous = err;
  }
}

TEST(ExtractRange, SwitchAnglesInsideTheRangeAreExact) {
  test::AnalyticSource src;
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 1.0, models::RateGate{"lever", +1}});
  const Samples s = range_samples(src, scene, 0.3, 2.5, 10);
  const auto* roots = s.roots_of("r_lever");
  ASSERT_NE(roots, nullptr);
  ASSERT_EQ(roots->size(), 1u);  // cos q = 0 once in [0.3, 2.5], no wrap-around interval
  EXPECT_NEAR((*roots)[0], M_PI / 2, 1e-12);
}

TEST(ExtractRange, CsvRoundTripKeepsTheRangeAndItsEdges) {
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  const Samples s = range_samples(src, scene, 0.3, 2.5, 10, Method::Kinetostatic, "dead point");
  const Samples r = parse_samples_csv(format_samples_csv(s), "t.csv");
  EXPECT_FALSE(r.periodic);
  EXPECT_EQ(r.min_edge, "dead point");
  EXPECT_EQ(r.max_edge, "declared limit");
  ASSERT_EQ(r.q.size(), s.q.size());
  EXPECT_NEAR(r.q.back(), 2.5, 1e-12);
  EXPECT_NE(format_samples_csv(s).find("periodic=0"), std::string::npos);
  EXPECT_THROW(parse_samples_csv(std::string(format_samples_csv(s)).replace(
                                     format_samples_csv(s).find("edges=dead_point"), 16, "edges=nowhere,x"),
                                 "t.csv"),
               TableError);
}

// The measurement behind docs/theory.md ("Range tables"): the same mechanism (the analytic
// slider-crank, whose crank turns fully) tabulated periodically over 360° and over the range
// [30°, 150°] at the same grid; errors of m1 at the interval midpoints inside the range.
TEST(ExtractRange, NotAKnotRangeTablesAreAsAccurateAsPeriodicOnes) {
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  for (double deg : {10.0, 5.0, 2.0}) {
    ExtractOptions opt;
    opt.step_rad = deg * kDeg;
    const Samples per = extract_samples(src, scene, opt);
    const Samples rng = range_samples(src, scene, 30 * kDeg, 150 * kDeg, deg);
    const Table t_per = build_table(per, Interpolation::CubicSpline);
    const Table t_nak = build_table(rng, Interpolation::CubicSpline);
    const Table t_aki = build_table(rng, Interpolation::Akima);
    const Table t_fou = build_table(per, Interpolation::Fourier);  // the periodic default
    double e_per = 0, e_nak = 0, e_aki = 0, e_fou = 0, scale = 0;
    for (size_t i = 0; i + 1 < rng.q.size(); ++i) {
      const double q = 0.5 * (rng.q[i] + rng.q[i + 1]);
      const double exact = src.sc.m1(q);
      scale = std::max(scale, exact);
      e_per = std::max(e_per, std::abs(t_per.eval(0, q) - exact));
      e_nak = std::max(e_nak, std::abs(t_nak.eval(0, q) - exact));
      e_aki = std::max(e_aki, std::abs(t_aki.eval(0, q) - exact));
      e_fou = std::max(e_fou, std::abs(t_fou.eval(0, q) - exact));
    }
    // GSL's natural spline (zero curvature at the ends), for the record.
    std::vector<double> y = rng.columns[0];
    gsl_spline* nat = gsl_spline_alloc(gsl_interp_cspline, y.size());
    gsl_spline_init(nat, rng.q.data(), y.data(), y.size());
    double e_nat = 0;
    for (size_t i = 0; i + 1 < rng.q.size(); ++i) {
      const double q = 0.5 * (rng.q[i] + rng.q[i + 1]);
      e_nat = std::max(e_nat, std::abs(gsl_spline_eval(nat, q, nullptr) - src.sc.m1(q)));
    }
    gsl_spline_free(nat);
    std::printf("m1 max rel. error at %g°: periodic cubic %.3g (fourier %.3g), range not-a-knot %.3g, natural %.3g, "
                "akima %.3g\n",
                deg, e_per / scale, e_fou / scale, e_nak / scale, e_nat / scale, e_aki / scale);
    EXPECT_LT(e_nak, 4 * e_per) << deg;   // comparable to the periodic spline (measured 2–3×)
    EXPECT_LT(e_nak, e_nat) << deg;       // better than the natural spline's O(h²) ends
    EXPECT_LT(e_nak, e_aki) << deg;       // and better than Akima's O(h²)-ish local slopes
  }
}

// A reduced run on a range table: free motion (no potential) runs into the edge and stops with
// the edge's value and kind; inside a potential well it reverses and conserves its energy.
TEST(ExtractRange, ReducedModelStopsAtTheEdgeAndReversesInside) {
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  const Samples s = range_samples(src, scene, 0.3, 2.5, 5, Method::Kinetostatic, "dead point");
  const ReducedModel m = make_reduced_model(s, scene, Interpolation::CubicSpline);
  ReducedOptions opt;
  opt.duration_s = 5;
  opt.output_interval_s = 0.01;
  for (const char* integrator : {"rk8pd", "rk4-fixed"}) {
    opt.integrator = integrator;
    try {
      simulate_reduced(m, 1.0, 2.0, opt);
      FAIL() << integrator << ": did not stop";
    } catch (const models::NumericalError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("left the validity domain at q = 143.2394"), std::string::npos) << msg;  // 2.5 rad
      EXPECT_NE(msg.find("(declared limit)"), std::string::npos) << msg;
    }
    try {
      simulate_reduced(m, 1.0, -2.0, opt);
      FAIL() << integrator << ": did not stop";
    } catch (const models::NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("q = 17.188733"), std::string::npos) << e.what();  // 0.3 rad
      EXPECT_NE(std::string(e.what()).find("(dead point)"), std::string::npos) << e.what();
    }
  }
  // V = k (1 − cos q) has its well at q = 0: tabulate [−1.2, 1.2] and start at rest from 0.5.
  test::AnalyticSource well;
  well.k = 2.0;
  const Samples w = range_samples(well, scene, -1.2, 1.2, 2);
  const ReducedModel mw = make_reduced_model(w, scene, Interpolation::CubicSpline);
  opt.integrator = "rk8pd";
  opt.tolerance = 1e-10;
  const auto ts = simulate_reduced(mw, 0.5, 0.0, opt);
  int reversals = 0;
  for (size_t i = 1; i < ts.qdot.size(); ++i) reversals += (ts.qdot[i - 1] > 0) != (ts.qdot[i] > 0) ? 1 : 0;
  EXPECT_GE(reversals, 4);
  for (size_t i = 0; i < ts.t.size(); ++i) {
    EXPECT_LE(std::abs(ts.q[i]), 0.5 + 1e-6);
    EXPECT_NEAR(ts.energy[i], ts.energy[0], 1e-6 * ts.energy[0]);
  }
}

}  // namespace
}  // namespace rdyn::reduced
