/* Shared by the C++ and the C consumer: a PD cadence controller on the crank speed that
 * commands the hip torque, the check of the cadence it holds, and step-time statistics.
 * Plain C99, header only (this is an outside project: nothing here comes from rdyn). */
#ifndef CADENCE_LOOP_H
#define CADENCE_LOOP_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define LOOP_PI 3.14159265358979323846

/* The run (issue #12): a 1 kHz controller for 60 s that must hold 1 Hz within 1 %. It starts
 * at half the cadence, so the drive command has real work to do; revolutions that end after
 * SETTLE_S are checked. */
static const double kStep_s = 1e-3;
static const long kSteps = 60000;
static const double kTarget_Hz = 1.0;
static const double kStart_Hz = 0.5;
static const double kSettle_s = 20.0;
static const double kTolerance = 0.01; /* relative */

/* T = T_ff + Kp (ω_ref − q̇) − Kd q̈, clamped to what a hip can push (no pulling).
 * T_ff is the scene's hip torque (the original authors' value holding about 1 Hz). The gains
 * are sized on the bicycle's crank inertia (~80 kg·m² with the road-equivalent flywheel)
 * and the ~0.3 N·m of mean crank torque per N·m of hip torque (two thighs, ~0.9 rad of swing
 * each per turn, bicycle.yaml): Kp = 400 N·m·s gives a closed-loop time constant of ~0.7 s
 * and leaves the PD's steady offset, (T_ff − T_needed)/Kp, near 0.2 % of the cadence. Kd
 * damps the speed ripple of the gated torque; q̈ comes from the model, so no differentiation
 * noise. */
typedef struct {
  double kp;          /* [N·m per rad/s] */
  double kd;          /* [N·m per rad/s²] */
  double feedforward; /* [N·m] */
  double t_min, t_max;
} cadence_pd;

static double cadence_pd_torque(const cadence_pd* c, double qdot, double qddot) {
  const double target = 2.0 * LOOP_PI * kTarget_Hz;
  double t = c->feedforward + c->kp * (target - qdot) - c->kd * qddot;
  if (t < c->t_min) t = c->t_min;
  if (t > c->t_max) t = c->t_max;
  return t;
}

/* Both readings of "holds 1 Hz within 1 %" after the settling time: the mean cadence of each
 * revolution, 1 / (time between two crossings of q0 + 2πk, interpolated inside the step), and
 * the crank speed at every step. */
typedef struct {
  double q_next;        /* next boundary [rad] */
  double t_last;        /* last crossing [s], negative before the first */
  int checked;          /* revolutions that ended after the settling time */
  int outside;          /* ... of which off the target by more than kTolerance */
  long samples_outside; /* steps after the settling time whose crank speed is off by more */
  double f_min, f_max, qdot_min, qdot_max;
} cadence_meter;

static void cadence_meter_init(cadence_meter* m, double q0) {
  m->q_next = q0 + 2.0 * LOOP_PI;
  m->t_last = -1.0;
  m->checked = m->outside = 0;
  m->samples_outside = 0;
  m->f_min = m->qdot_min = INFINITY;
  m->f_max = m->qdot_max = -INFINITY;
}

static void cadence_meter_update(cadence_meter* m, double t0, double q0, double t1, double q1,
                                 double qdot1) {
  if (t1 > kSettle_s) {
    if (qdot1 < m->qdot_min) m->qdot_min = qdot1;
    if (qdot1 > m->qdot_max) m->qdot_max = qdot1;
    if (fabs(qdot1 / (2.0 * LOOP_PI) - kTarget_Hz) > kTolerance * kTarget_Hz) ++m->samples_outside;
  }
  while (q1 >= m->q_next && q1 > q0) {
    const double tc = t0 + (t1 - t0) * (m->q_next - q0) / (q1 - q0);
    if (m->t_last >= 0.0 && tc > kSettle_s) {
      const double f = 1.0 / (tc - m->t_last);
      if (f < m->f_min) m->f_min = f;
      if (f > m->f_max) m->f_max = f;
      ++m->checked;
      if (fabs(f - kTarget_Hz) > kTolerance * kTarget_Hz) ++m->outside;
    }
    m->t_last = tc;
    m->q_next += 2.0 * LOOP_PI;
  }
}

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

/* Prints the run's summary; returns the exit status (0: the cadence held). Timing is
 * reported, not asserted (CI machines vary). Sorts step_us in place. */
static int cadence_report(const char* api, const cadence_meter* m, double* step_us, long n) {
  qsort(step_us, (size_t)n, sizeof(double), compare_doubles);
  printf(
      "%s: %ld steps of %g s; step time median %.2f us, 99.9th percentile %.2f us, worst %.2f us\n",
      api, n, kStep_s, step_us[n / 2], step_us[n - 1 - n / 1000], step_us[n - 1]);
  printf(
      "%s: %d revolutions after %g s: cadence %.5f..%.5f Hz (target %g Hz within %g %%), crank "
      "speed "
      "%.5f..%.5f Hz\n",
      api, m->checked, kSettle_s, m->f_min, m->f_max, kTarget_Hz, 100 * kTolerance,
      m->qdot_min / (2 * LOOP_PI), m->qdot_max / (2 * LOOP_PI));
  if (m->checked < 30) {
    fprintf(stderr, "%s: only %d revolutions after the settling time (expected ~40)\n", api,
            m->checked);
    return 1;
  }
  if (m->outside > 0 || m->samples_outside > 0) {
    fprintf(stderr, "%s: %d revolutions and %ld steps off the target cadence by more than %g %%\n",
            api, m->outside, m->samples_outside, 100 * kTolerance);
    return 1;
  }
  return 0;
}

#endif
