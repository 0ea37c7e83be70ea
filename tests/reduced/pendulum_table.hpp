// A pendulum that asks for its pivot's reaction and the shaking load, as a scene file and the
// table `rdyn extract` writes for it, for the runtime's and the C API's joint-output tests:
// a bob of m = 1.5 kg whose centre of mass sits l = 0.4 m from the pivot (I = 0.02 kg·m² about
// it), q = 0 horizontal, gravity −9.81 m/s² along y.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_table.hpp"

namespace rdyn::test {

inline constexpr double kPendulumMass_kg = 1.5, kPendulumArm_m = 0.4, kPendulumInertia_kgm2 = 0.02;

// Writes DIR/pendulum.yaml and DIR/pendulum.csv (10° grid); returns the exit status of the extraction.
inline int write_pendulum_table(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "pendulum.yaml")
      << "name: pendulum\n"
         "bodies: [{name: bob, mass_kg: 1.5, com_m: [0.4, 0], inertia_kgm2: 0.02}]\n"
         "joints: [{name: pivot, type: revolute, parent: ground, parent_point: [0, 0], child: bob}]\n"
         "independent: pivot\n"
         "gravity: {enabled: true, g_m_s2: [0, -9.81]}\n"
         "outputs: {reactions: [pivot], shaking: true, joints: [pivot]}\n"
         "initial: {q_deg: -90, qdot: 3.0}\n";
  return extract_table_with_cli((dir / "pendulum.yaml").string(), "10", (dir / "pendulum.csv").string());
}

}  // namespace rdyn::test
