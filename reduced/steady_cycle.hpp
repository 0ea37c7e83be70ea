// The steady periodic cycle of the reduced model, without time stepping where q̇ keeps its sign.
//
// With q as the independent variable and u = q̇²/2 (so du/dq = q̈), Eksergian's equation
//   m1(q) q̈ + m2(q) q̇² = F*(q, q̇)   reads   m1(q) du/dq + 2 m2(q) u = F*(q, s·√(2u)),
// s = sign q̇ (fixed over the cycle), and time follows from dt = dq/q̇ (docs/theory.md §6a).
// One pass over a period P of the table maps u at the section q_s to u after the period,
// u ↦ Φ(u); the steady cycle is the fixed point u = Φ(u), found by the secant method on
// Φ(u) − u. Rate-gated loads switch where sign(r_g(q)·q̇) changes: with s fixed those are
// position-only switch angles, integrated as breakpoints. The time-stepping route (Poincaré
// map by the secant method over reduced::AdaptiveIntegrator revolutions) is the fallback when
// q̇ does not keep its sign, and the cross-check.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

// Valid ranges of the options (TableError naming the range, before any work).
inline constexpr int kMinCycleSamples = 16;
inline constexpr int kMaxCycleSamples = 1000000;
inline constexpr int kMaxCyclePasses = 1000;

struct SteadyCycleOptions {
  double q_section = 0.0;    // section q_s where the cycle starts and ends [rad], finite
  double qdot_guess = 0.0;   // first guess of q̇ at q_s [rad/s], finite and non-zero: its sign is the direction
  double tolerance = 1e-10;  // local error per step, relative, [kMinTolerance, kMaxTolerance]
  int samples = 1440;        // samples per cycle for the extremes (refined between samples), [16, 10⁶]
  int max_passes = 60;       // cycles the fixed-point search may integrate, [1, 1000]
  // Sample the cycle for the extremes of |q̇| and the peak constraint forces (about one more
  // pass). Without, the first integral leaves speed_min = speed_max = |qdot_section|,
  // speed_fluctuation 0 and no peak forces (a search that only needs period and section speed);
  // the time-stepping route always samples.
  bool extremes = true;
};

enum class CycleMethod { FirstIntegral, TimeStepping };
std::string cycle_method_name(CycleMethod m);  // "first-integral" | "time-stepping"

struct SteadyCycle {
  CycleMethod method = CycleMethod::FirstIntegral;
  double period_s = 0.0;         // time for q to advance by the table's period P (one cycle)
  double mean_cadence_hz = 0.0;  // cycles per second, 1 / period_s
  double qdot_section = 0.0;     // q̇ at q_s on the cycle [rad/s] (sign of the direction)
  double speed_min = 0.0, speed_max = 0.0;  // extremes of |q̇| over the cycle [rad/s]
  double speed_fluctuation = 0.0;  // (speed_max − speed_min) / mean speed, mean speed = P / period_s
  // Work per cycle [J] and mean power [W]. Drive: joint torques and motors (signed);
  // dissipated: minus the resistances' work. Steady: drive = dissipated (V is periodic).
  double drive_work_J = 0.0, dissipated_work_J = 0.0;
  double drive_power_W = 0.0, dissipated_power_W = 0.0;
  // Per requested constraint force (ReducedModel::force_names): max |F_E| over the cycle
  // [N or N·m] and where it occurs [rad]. F_E from the constraint line
  // me1 q̈ + me2 q̇² = F_E + Q_x with q̈ from Eksergian's equation.
  std::vector<double> peak_force_N, peak_force_q;
  int passes = 0;              // cycles integrated by the fixed-point search (Poincaré-map evaluations)
  long steps = 0;              // integration steps over all passes and samples
  long rhs_evaluations = 0;    // Eksergian right-hand sides (first integral; 0 for time stepping)
};

// Throws TableError (exit 2) naming the option and its range.
void check_steady_cycle_options(const SteadyCycleOptions& opt);

// The steady cycle by the first integral (no time stepping). Throws TableError on options out
// of range, NumericalError when there is no cycle with q̇ of one sign (the mechanism stalls or
// turns back from every start speed tried, the table is not periodic, or the search does not
// converge within max_passes): callers fall back to calc_steady_cycle_time_stepping.
SteadyCycle calc_steady_cycle(const ReducedModel& m, const SteadyCycleOptions& opt);

// The steady cycle as the fixed point of the Poincaré map at q_s (speed after one period as a
// function of the starting speed, by the secant method), each map evaluation one adaptive
// time integration (rk8pd at opt.tolerance, at most 5·10⁴ steps) to q_s ± P. Throws
// NumericalError when no cycle is found within max_passes (a stall: a period not completed
// within 20 periods at the start speed or within the steps) or the cycle found still gains
// energy (a runaway).
SteadyCycle calc_steady_cycle_time_stepping(const ReducedModel& m, const SteadyCycleOptions& opt);

// First integral first, time stepping when it does not apply (its NumericalError); throws the
// time-stepping route's NumericalError when neither finds a cycle.
SteadyCycle find_steady_cycle(const ReducedModel& m, const SteadyCycleOptions& opt);

// Single passes of the first integral, for callers that solve for the cycle together with
// other unknowns (calibration: the steady cycle and the load that holds a cadence, in one
// Newton iteration instead of a search over loads each holding a search over speeds). The
// breakpoints are fixed at construction: the model's load values (torques, motors,
// resistance coefficients) may change between passes, its gates and table may not. Passes
// after the first replay its step grid (§6a), so a pass is a smooth function of u0 and of
// the load values, as finite differences need.
class CyclePasses {
 public:
  // opt.qdot_guess gives the direction (its sign); opt.q_section the section. Throws TableError
  // on options out of range, NumericalError on a table that is not periodic.
  CyclePasses(const ReducedModel& m, const SteadyCycleOptions& opt);
  ~CyclePasses();
  CyclePasses(const CyclePasses&) = delete;
  CyclePasses& operator=(const CyclePasses&) = delete;

  struct Pass {
    bool completed = false;  // false: q̇ reached zero within the period (a stall)
    double u_end = 0.0;      // u = q̇²/2 after one period [rad²/s²]
    double period_s = 0.0;   // its duration
    double work_nc_J = 0.0;  // work of every non-conservative load over it
    double work_brakes_J = 0.0;  // of the resistances (≤ 0)
  };
  // One period from u0 = q̇0²/2 > 0 (finite) at the section.
  Pass run(double u0);
  int passes() const { return passes_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int passes_ = 0;
};

}  // namespace rdyn::reduced
