// The study sections of a scene: `outputs` (constraint forces, joint reactions, shaking, bodies),
// `simulation`, `validation` and `optimize`. Internal to models/ (read_scene calls them); the
// public interface is models/scene_yaml.hpp.
#pragma once

#include "models/scene.hpp"
#include "models/yaml_fields.hpp"

namespace rdyn::models::yaml {

// `outputs`: needs the mechanism read (joint and body names).
void read_outputs(const Fields& top, const Context& ctx, Scene& s);
// `simulation`: integrator settings of the full model.
void read_simulation(const Fields& top, const Context& ctx, Scene& s);
// `validation`: thresholds, the reference's settings, calibration and comparison values.
void read_validation(const Fields& top, const Context& ctx, Scene& s);
// `optimize`: the strategy's loads, harmonics and objective (needs the loads read).
void read_optimize(const Fields& f, Scene& s);

}  // namespace rdyn::models::yaml
