/* rdyn reduced runtime, C interface (C99; for C programs, Simulink S-functions, any FFI).
 *
 * A thin layer over reduced/runtime.hpp: the same model, workspace and fixed RK4 step on
 * Eksergian's equation m1(q) q̈ + m2(q) q̇² = F*. Opaque handles; every function returns a
 * status and never lets an exception or abort through. Loading allocates and may fail with
 * a message; rdyn_step and the getters allocate nothing. A scene that asks for joint outputs
 * takes the table `rdyn extract` writes for it; its reactions and shaking load come with each
 * step (rdyn_get_joint_outputs).
 *
 *   rdyn_model* m; rdyn_workspace* ws; char msg[512];
 *   if (rdyn_model_load("bicycle.csv", "bicycle", &m, msg, sizeof msg) != RDYN_OK) puts(msg);
 *   rdyn_workspace_new(m, &ws);
 *   rdyn_drive d = {RDYN_DRIVE_TORQUE, 69.7};
 *   rdyn_step(m, ws, 1e-3, d);
 *   rdyn_state s; rdyn_get_state(ws, &s);   (s.q, s.qdot, s.qddot)
 *   double T; rdyn_drive_torque(m, ws, q, qdot, qddot, &T);   (inverse: feed-forward)
 *   rdyn_workspace_free(ws); rdyn_model_free(m);
 */
#ifndef RDYN_REDUCED_H
#define RDYN_REDUCED_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rdyn_model rdyn_model;         /* immutable: table + scene loads */
typedef struct rdyn_workspace rdyn_workspace; /* per-run state of one model */

/* Status codes. 1..7 are rdyn::reduced::Status; the rest belong to the C layer. */
typedef enum rdyn_status {
  RDYN_OK = 0,
  RDYN_BAD_STEP = 1,        /* dt not finite or outside [1e-7, 1] s */
  RDYN_BAD_DRIVE = 2,       /* drive not finite, a commanded torque beyond ±1e6, or a torque for a scene
                               without joint torques (only the scene's own drive, scale 1, is accepted) */
  RDYN_BAD_STATE = 3,       /* q, q̇ not finite, |q̇| > 1e4, or q outside the table */
  RDYN_WRONG_WORKSPACE = 4, /* workspace made for another model */
  RDYN_NON_FINITE = 5,      /* the step produced a non-finite value; state kept */
  RDYN_LEFT_TABLE = 6,      /* q left a non-periodic table; state kept */
  RDYN_DIVERGED = 7,        /* energy balance broke: table or step too coarse; state kept */
  RDYN_BAD_ARGUMENT = 20,   /* a null handle or pointer, an index out of range */
  RDYN_BAD_INPUT = 21,      /* load: table or scene unreadable, malformed, or not matching */
  RDYN_NUMERICAL = 22,      /* load: a computation failed on valid input */
  RDYN_OUT_OF_MEMORY = 23,
  RDYN_INTERNAL = 24 /* anything else (a bug: please report the message) */
} rdyn_status;

/* One sentence describing a status (static storage, never NULL; "unknown status" for a
 * number that is none). */
const char* rdyn_status_string(int status);

typedef enum rdyn_drive_mode {
  RDYN_DRIVE_SCALE = 0, /* value multiplies every scene joint torque */
  RDYN_DRIVE_TORQUE = 1 /* every scene joint torque becomes ±value (its scene sign) [N·m or N] */
} rdyn_drive_mode;

typedef struct rdyn_drive {
  int mode;     /* an rdyn_drive_mode; any other number is refused (RDYN_BAD_DRIVE) */
  double value; /* factor [-] or torque magnitude [N·m or N] */
} rdyn_drive;

typedef struct rdyn_state {
  double t;      /* [s] since the last reset */
  double q;      /* [rad or m] */
  double qdot;   /* [rad/s or m/s] */
  double qddot;  /* [rad/s² or m/s²] */
  double work;   /* work of the non-conservative loads since the reset [J] */
  double energy; /* ½ m1 q̇² + V [J] */
} rdyn_state;

/* Loads a table written by `rdyn extract` and checks it against the scene (a shipped scene
 * name or a YAML path). On failure *model is NULL and message (if not NULL) holds a
 * NUL-terminated explanation, truncated to message_size. */
rdyn_status rdyn_model_load(const char* table_csv_path, const char* scene, rdyn_model** model,
                            char* message, size_t message_size);
void rdyn_model_free(rdyn_model* model); /* NULL is allowed */

/* The scene's initial state [rad or m], [rad/s or m/s]. */
rdyn_status rdyn_model_initial_state(const rdyn_model* model, double* q, double* qdot);
/* Requested constraint forces: count, and the name of force k (owned by the model). */
int rdyn_model_num_forces(const rdyn_model* model);
const char* rdyn_model_force_name(const rdyn_model* model, int k); /* NULL when out of range */
/* The scene's joint outputs (outputs.joints, reactions, shaking): count, and the name of output
 * k (owned by the model), as `rdyn simulate --model reduced` names its columns: q_<joint>,
 * qdot_<joint>, qddot_<joint> [rad or m, /s, /s²], R_<joint>_x, R_<joint>_y [N] (a prismatic
 * joint adds R_<joint>_normal [N], R_<joint>_M [N·m]), shaking_x, shaking_y [N], shaking_M [N·m].
 * 0 and NULL when the scene asks for none. */
int rdyn_model_num_joint_outputs(const rdyn_model* model);
const char* rdyn_model_joint_output_name(const rdyn_model* model, int k);
/* The scene's joint torques the drive commands: count, and the scene value of torque i. */
int rdyn_model_num_drive_torques(const rdyn_model* model);
rdyn_status rdyn_model_drive_torque(const rdyn_model* model, int i, double* nominal);

/* A workspace at the scene's initial state (allocates once). */
rdyn_status rdyn_workspace_new(const rdyn_model* model, rdyn_workspace** workspace);
void rdyn_workspace_free(rdyn_workspace* workspace); /* NULL is allowed */

/* t = 0, W = 0, state (q, q̇), drive; load gates from that state. */
rdyn_status rdyn_reset(const rdyn_model* model, rdyn_workspace* workspace, double q, double qdot,
                       rdyn_drive drive);
/* One fixed RK4 step of dt [s] with the drive held over it. */
rdyn_status rdyn_step(const rdyn_model* model, rdyn_workspace* workspace, double dt,
                      rdyn_drive drive);

rdyn_status rdyn_get_state(const rdyn_workspace* workspace, rdyn_state* state);
/* The inverse of rdyn_step: the generalized force [N·m or N] the drive must add on q for the
 * reduced model to move with (q, q̇, q̈): m1(q) q̈ + m2(q) q̇² − F*(q, q̇), every scene load in
 * F* with the joint torques as last commanded (the scene's until a reset or step commands
 * others), gates from the sign of q̇ — what `rdyn drive --model reduced` gives per row. Inputs
 * must be finite, |q̇| ≤ 1e4, |q̈| ≤ 1e8, q in the table (else RDYN_BAD_STATE; *drive untouched).
 * Does not change the workspace's state; allocates nothing. */
rdyn_status rdyn_drive_torque(const rdyn_model* model, rdyn_workspace* workspace, double q,
                              double qdot, double qddot, double* drive);

/* Copies min(n, number of forces) constraint forces F_E,k [N] into forces. */
rdyn_status rdyn_get_forces(const rdyn_workspace* workspace, double* forces, int n);
/* Copies min(n, number of joint outputs) joint outputs at the current state into out, in the
 * order of rdyn_model_joint_output_name: what `rdyn simulate --model reduced` writes in a row
 * at the same state. Computed with every step; allocates nothing. */
rdyn_status rdyn_get_joint_outputs(const rdyn_workspace* workspace, double* out, int n);

/* What `status`, just returned by a call on this workspace, means — for RDYN_BAD_DRIVE and
 * RDYN_BAD_STATE the one cause of that refusal (a value not finite, no joint torque to command, a
 * torque beyond 1e6, |q̇| beyond 1e4, q outside the table, ...), else rdyn_status_string(status).
 * A static string; allocates nothing. */
const char* rdyn_workspace_message(const rdyn_workspace* workspace, int status);

#ifdef __cplusplus
}
#endif

#endif /* RDYN_REDUCED_H */
