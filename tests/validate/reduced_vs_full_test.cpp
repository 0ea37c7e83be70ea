// The product's claim on the reference case: the reduced model reproduces full forward
// dynamics, and converges as the grid is refined.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/forward_dynamics.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/build_reduced.hpp"

namespace rdyn::validate {
namespace {

struct Errors {
  double qdot, force;  // max |full − reduced| after 1 s, relative to the full model's peak
};

Errors compare(const models::TimeSeries& f, const models::TimeSeries& r) {
  double pq = 0, pf = 0, eq = 0, ef = 0;
  for (size_t i = 0; i < f.t.size(); ++i) {
    if (f.t[i] < 1.0) continue;
    pq = std::max(pq, std::abs(f.qdot[i]));
    pf = std::max(pf, std::abs(f.forces[0][i]));
    eq = std::max(eq, std::abs(f.qdot[i] - r.qdot[i]));
    ef = std::max(ef, std::abs(f.forces[0][i] - r.forces[0][i]));
  }
  return {eq / pq, ef / pf};
}

class BicycleReducedVsFull : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new models::Scene(models::load_scene("bicycle"));
    engine::FullModel model(*scene_);
    engine::ForwardOptions opt;
    opt.duration_s = 5.0;
    opt.output_interval_s = 0.005;
    opt.tolerance = 1e-10;
    full_ = new models::TimeSeries(engine::simulate_full(model, opt));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete full_;
  }
  static Errors run(double grid_deg, reduced::Interpolation interp) {
    const auto e = extract_from_full(*scene_, grid_deg, reduced::Method::Kinetostatic);
    const auto m = reduced::make_reduced_model(e.samples, *scene_, interp);
    reduced::ReducedOptions opt;
    opt.duration_s = 5.0;
    opt.output_interval_s = 0.005;
    return compare(*full_, reduced::simulate_reduced(m, scene_->initial.q, scene_->initial.qdot, opt));
  }
  static models::Scene* scene_;
  static models::TimeSeries* full_;
};
models::Scene* BicycleReducedVsFull::scene_ = nullptr;
models::TimeSeries* BicycleReducedVsFull::full_ = nullptr;

TEST_F(BicycleReducedVsFull, WithinHalfAPercentAtTenDegrees) {
  const Errors e = run(10, reduced::Interpolation::Fourier);
  EXPECT_LT(e.qdot, 5e-3);
  EXPECT_LT(e.force, 5e-3);
  RecordProperty("qdot_error_10deg", std::to_string(e.qdot));
  RecordProperty("knee_error_10deg", std::to_string(e.force));
}

TEST_F(BicycleReducedVsFull, ConvergesAsTheGridIsRefined) {
  for (auto interp : {reduced::Interpolation::CubicSpline, reduced::Interpolation::Fourier}) {
    const Errors e20 = run(20, interp), e10 = run(10, interp), e5 = run(5, interp);
    EXPECT_LT(e10.force, e20.force / 4) << reduced::interpolation_name(interp);
    EXPECT_LT(e5.force, e10.force / 4) << reduced::interpolation_name(interp);
    EXPECT_LT(e5.qdot, e10.qdot) << reduced::interpolation_name(interp);
  }
}

}  // namespace
}  // namespace rdyn::validate
