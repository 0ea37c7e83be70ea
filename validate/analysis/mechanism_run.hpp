// A run whose every joint coordinate is output (q_<joint> for all joints), so that the drawing
// (validate/report/mechanism_drawing.hpp) can place every body at every output time: the full
// model (Simbody forward dynamics) or the reduced model (table extracted now, Eksergian's
// equation, joint coordinates from the table's p_/k_ columns).
#pragma once

#include <string>

#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::validate {

// `scene` with outputs.joints = every joint (scene order); the rest unchanged.
models::Scene with_every_joint_output(const models::Scene& scene);

// Simulates with_every_joint_output(scene) from its initial state: model "full" or "reduced"
// (grid 10°, fourier, rk8pd at 1e-8: the simulate command's defaults). Throws as simulate does.
models::TimeSeries simulate_every_joint(const models::Scene& scene, const std::string& model, double duration_s,
                                        double output_interval_s);

// Every joint's coordinate at row `row` of such a run (scene.joints order).
std::vector<double> joint_coordinates(const models::Scene& scene, const models::TimeSeries& ts, size_t row);

}  // namespace rdyn::validate
