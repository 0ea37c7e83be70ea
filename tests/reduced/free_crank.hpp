// Shared by the reduced integrators' tests (simulate_reduced_test, adaptive_integrator_test).
#pragma once

#include <cmath>
#include <exception>
#include <functional>
#include <string>

#include "analytic_source.hpp"
#include "reduced/extract.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::test {

// The analytic slider-crank (no loads) on a 10° cubic table: it turns freely from q̇ = 10 rad/s.
inline reduced::ReducedModel free_crank() {
  AnalyticSource src;
  reduced::ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  const auto scene = analytic_scene();
  return reduced::make_reduced_model(reduced::extract_samples(src, scene, opt), scene,
                                     reduced::Interpolation::CubicSpline);
}

// The message of what f throws ("" when it does not).
inline std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace rdyn::test
