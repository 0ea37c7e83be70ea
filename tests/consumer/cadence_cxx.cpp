// Cadence control of the reduced bicycle through the C++ runtime API (rdyn::reduced).
// Usage: cadence_cxx TABLE.csv [SCENE]   (SCENE defaults to the installed bicycle scene)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <rdyn/reduced/runtime.hpp>
#include <string>
#include <vector>

#include "cadence_loop.h"

namespace rr = rdyn::reduced;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s TABLE.csv [SCENE]\n", argv[0]);
    return 2;
  }
  const std::string scene = argc > 2 ? argv[2] : RDYN_CONSUMER_SCENE;
  rr::RuntimeModel model;
  try {
    model = rr::load_runtime_model(argv[1], scene);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cadence_cxx: %s\n", e.what());
    return 2;
  }
  if (model.drive_nominal.empty()) {
    std::fprintf(stderr, "cadence_cxx: the scene has no drive torque to command\n");
    return 2;
  }
  const cadence_pd pd{400.0, 20.0, std::abs(model.drive_nominal[0]), 0.0, 250.0};

  // Open loop first (the scene's own torque): from half the cadence it is still far from
  // 1 Hz after the settling time, so a drive command that were ignored would fail below.
  rr::RuntimeWorkspace ws(model);
  const double qdot_start = 2 * LOOP_PI * kStart_Hz;
  if (rr::reset(model, ws, model.initial_q, qdot_start) != rr::Status::Ok) return 1;
  while (ws.get_t() < kSettle_s - 1e-9)
    if (const auto s = rr::step(model, ws, kStep_s, rr::Drive::scaled(1.0)); s != rr::Status::Ok) {
      std::fprintf(stderr, "cadence_cxx: open-loop step failed: %s\n", rr::status_message(s));
      return 1;
    }
  const double open_loop_hz = ws.get_qdot() / (2 * LOOP_PI);
  std::printf("cxx: open loop from %g Hz: %.4f Hz after %g s\n", kStart_Hz, open_loop_hz,
              kSettle_s);
  if (std::abs(open_loop_hz - kTarget_Hz) <= kTolerance * kTarget_Hz) {
    std::fprintf(
        stderr,
        "cadence_cxx: the open-loop run already holds the target: the check proves nothing\n");
    return 1;
  }

  // Closed loop at 1 kHz.
  if (rr::reset(model, ws, model.initial_q, qdot_start) != rr::Status::Ok) return 1;
  cadence_meter meter;
  cadence_meter_init(&meter, model.initial_q);
  std::vector<double> step_us(kSteps);
  for (long i = 0; i < kSteps; ++i) {
    const double torque = cadence_pd_torque(&pd, ws.get_qdot(), ws.get_qddot());
    const double t0 = ws.get_t(), q0 = ws.get_q();
    const auto start = std::chrono::steady_clock::now();
    const rr::Status s = rr::step(model, ws, kStep_s, rr::Drive::torque(torque));
    step_us[i] =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    if (s != rr::Status::Ok) {
      std::fprintf(stderr, "cadence_cxx: step %ld failed: %s\n", i, rr::status_message(s));
      return 1;
    }
    cadence_meter_update(&meter, t0, q0, ws.get_t(), ws.get_q(), ws.get_qdot());
  }
  std::printf("cxx: knee force at the end %.1f N, hip torque %.2f N·m\n",
              ws.get_forces().empty() ? 0.0 : ws.get_forces()[0], ws.get_drive_torques()[0]);
  return cadence_report("cxx", &meter, step_us.data(), kSteps);
}
