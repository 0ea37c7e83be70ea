/* Cadence control of the reduced bicycle through the C API (rdyn_reduced.h).
 * Usage: cadence_c TABLE.csv [SCENE]   (SCENE defaults to the installed bicycle scene) */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <rdyn/reduced/rdyn_reduced.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "cadence_loop.h"

static double now_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return 1e6 * (double)ts.tv_sec + 1e-3 * (double)ts.tv_nsec;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s TABLE.csv [SCENE]\n", argv[0]);
    return 2;
  }
  const char* scene = argc > 2 ? argv[2] : RDYN_CONSUMER_SCENE;
  char message[1024];
  rdyn_model* model = NULL;
  rdyn_workspace* ws = NULL;
  if (rdyn_model_load(argv[1], scene, &model, message, sizeof message) != RDYN_OK) {
    fprintf(stderr, "cadence_c: %s\n", message);
    return 2;
  }
  double nominal = 0.0, q0 = 0.0, qdot0 = 0.0;
  if (rdyn_model_drive_torque(model, 0, &nominal) != RDYN_OK ||
      rdyn_workspace_new(model, &ws) != RDYN_OK ||
      rdyn_model_initial_state(model, &q0, &qdot0) != RDYN_OK) {
    fprintf(stderr, "cadence_c: no drive torque, or no workspace\n");
    rdyn_model_free(model);
    return 2;
  }
  const cadence_pd pd = {400.0, 20.0, fabs(nominal), 0.0, 250.0};
  const rdyn_drive nominal_drive = {RDYN_DRIVE_SCALE, 1.0};
  rdyn_status s = rdyn_reset(model, ws, q0, 2 * LOOP_PI * kStart_Hz, nominal_drive);
  double* step_us = malloc(sizeof(double) * (size_t)kSteps);
  double forces[8] = {0};
  const int n_forces = rdyn_model_num_forces(model) < 8 ? rdyn_model_num_forces(model) : 8;
  cadence_meter meter;
  cadence_meter_init(&meter, q0);
  rdyn_state st;
  rdyn_get_state(ws, &st);
  for (long i = 0; s == RDYN_OK && step_us && i < kSteps; ++i) {
    const rdyn_drive drive = {RDYN_DRIVE_TORQUE, cadence_pd_torque(&pd, st.qdot, st.qddot)};
    const double t0 = st.t, q_before = st.q, start = now_us();
    s = rdyn_step(model, ws, kStep_s, drive);
    step_us[i] = now_us() - start;
    rdyn_get_state(ws, &st);
    cadence_meter_update(&meter, t0, q_before, st.t, st.q, st.qdot);
  }
  int status = 1;
  if (!step_us) {
    fprintf(stderr, "cadence_c: out of memory\n");
  } else if (s != RDYN_OK) {
    fprintf(stderr, "cadence_c: %s\n", rdyn_status_string(s));
  } else {
    rdyn_get_forces(ws, forces, n_forces);
    printf("c: knee force at the end %.1f N (%s)\n", forces[0],
           n_forces > 0 ? rdyn_model_force_name(model, 0) : "-");
    status = cadence_report("c", &meter, step_us, kSteps);
  }
  free(step_us);
  rdyn_workspace_free(ws);
  rdyn_model_free(model);
  return status;
}
