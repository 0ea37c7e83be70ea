// The C interface (rdyn_reduced.h) over reduced/runtime.hpp: handles own the C++ objects,
// exceptions stop here and become status codes and messages.
#include "reduced/rdyn_reduced.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "models/scene.hpp"
#include "reduced/runtime.hpp"

struct rdyn_model {
  rdyn::reduced::RuntimeModel model;
};
struct rdyn_workspace {
  rdyn::reduced::RuntimeWorkspace ws;
};

namespace {

using rdyn::reduced::Status;

// The C enum mirrors the C++ one value for value.
static_assert(RDYN_OK == static_cast<int>(Status::Ok) &&
              RDYN_BAD_STEP == static_cast<int>(Status::BadStep) &&
              RDYN_BAD_DRIVE == static_cast<int>(Status::BadDrive) &&
              RDYN_BAD_STATE == static_cast<int>(Status::BadState) &&
              RDYN_WRONG_WORKSPACE == static_cast<int>(Status::WrongWorkspace) &&
              RDYN_NON_FINITE == static_cast<int>(Status::NonFinite) &&
              RDYN_LEFT_TABLE == static_cast<int>(Status::LeftTable) &&
              RDYN_DIVERGED == static_cast<int>(Status::Diverged));

rdyn_status to_c(Status s) { return static_cast<rdyn_status>(static_cast<int>(s)); }

rdyn::reduced::Drive to_cpp(rdyn_drive d) {
  // Any other mode is passed on as a NaN value, which the runtime refuses as BadDrive.
  if (d.mode == RDYN_DRIVE_SCALE) return rdyn::reduced::Drive::scaled(d.value);
  if (d.mode == RDYN_DRIVE_TORQUE) return rdyn::reduced::Drive::torque(d.value);
  return rdyn::reduced::Drive::scaled(NAN);
}

void copy_message(const std::string& text, char* message, size_t size) {
  if (!message || size == 0) return;
  const size_t n = std::min(text.size(), size - 1);
  std::memcpy(message, text.data(), n);
  message[n] = '\0';
}

}  // namespace

extern "C" {

const char* rdyn_status_string(int status) {
  switch (status) {
    case RDYN_BAD_ARGUMENT:
      return "a null handle or pointer, or an index out of range";
    case RDYN_BAD_INPUT:
      return "the table or the scene is unreadable, malformed, or they do not match";
    case RDYN_NUMERICAL:
      return "a computation failed on valid input";
    case RDYN_OUT_OF_MEMORY:
      return "out of memory";
    case RDYN_INTERNAL:
      return "internal error";
    default:
      if (status >= RDYN_OK && status <= RDYN_DIVERGED)
        return rdyn::reduced::status_message(static_cast<Status>(status));
      return "unknown status";
  }
}

rdyn_status rdyn_model_load(const char* table_csv_path, const char* scene, rdyn_model** model,
                            char* message, size_t message_size) {
  copy_message("", message, message_size);
  if (!model) {
    copy_message("rdyn_model_load: model is NULL", message, message_size);
    return RDYN_BAD_ARGUMENT;
  }
  *model = nullptr;
  if (!table_csv_path || !scene) {
    copy_message("rdyn_model_load: table path or scene is NULL", message, message_size);
    return RDYN_BAD_ARGUMENT;
  }
  try {
    *model = new rdyn_model{rdyn::reduced::load_runtime_model(table_csv_path, scene)};
    return RDYN_OK;
  } catch (const rdyn::models::SceneError& e) {
    copy_message(e.what(), message, message_size);
    return RDYN_BAD_INPUT;
  } catch (const rdyn::reduced::TableError& e) {
    copy_message(e.what(), message, message_size);
    return RDYN_BAD_INPUT;
  } catch (const rdyn::models::NumericalError& e) {
    copy_message(e.what(), message, message_size);
    return RDYN_NUMERICAL;
  } catch (const std::bad_alloc&) {
    copy_message("out of memory", message, message_size);
    return RDYN_OUT_OF_MEMORY;
  } catch (const std::exception& e) {
    copy_message(std::string("internal error: ") + e.what(), message, message_size);
    return RDYN_INTERNAL;
  } catch (...) {
    copy_message("internal error", message, message_size);
    return RDYN_INTERNAL;
  }
}

void rdyn_model_free(rdyn_model* model) { delete model; }

rdyn_status rdyn_model_initial_state(const rdyn_model* model, double* q, double* qdot) {
  if (!model || !q || !qdot) return RDYN_BAD_ARGUMENT;
  *q = model->model.initial_q;
  *qdot = model->model.initial_qdot;
  return RDYN_OK;
}

int rdyn_model_num_forces(const rdyn_model* model) {
  return model ? static_cast<int>(model->model.force_names.size()) : 0;
}

const char* rdyn_model_force_name(const rdyn_model* model, int k) {
  if (!model || k < 0 || k >= rdyn_model_num_forces(model)) return nullptr;
  return model->model.force_names[k].c_str();
}

int rdyn_model_num_joint_outputs(const rdyn_model* model) {
  return model && model->model.joint_outputs ? static_cast<int>(model->model.joint_outputs->names.size()) : 0;
}

const char* rdyn_model_joint_output_name(const rdyn_model* model, int k) {
  if (!model || k < 0 || k >= rdyn_model_num_joint_outputs(model)) return nullptr;
  return model->model.joint_outputs->names[k].c_str();
}

int rdyn_model_num_drive_torques(const rdyn_model* model) {
  return model ? static_cast<int>(model->model.drive_nominal.size()) : 0;
}

rdyn_status rdyn_model_drive_torque(const rdyn_model* model, int i, double* nominal) {
  if (!model || !nominal || i < 0 || i >= rdyn_model_num_drive_torques(model))
    return RDYN_BAD_ARGUMENT;
  *nominal = model->model.drive_nominal[i];
  return RDYN_OK;
}

rdyn_status rdyn_workspace_new(const rdyn_model* model, rdyn_workspace** workspace) {
  if (!workspace) return RDYN_BAD_ARGUMENT;
  *workspace = nullptr;
  if (!model) return RDYN_BAD_ARGUMENT;
  try {
    *workspace = new rdyn_workspace{rdyn::reduced::RuntimeWorkspace(model->model)};
    return RDYN_OK;
  } catch (const std::bad_alloc&) {
    return RDYN_OUT_OF_MEMORY;
  } catch (...) {
    return RDYN_INTERNAL;
  }
}

void rdyn_workspace_free(rdyn_workspace* workspace) { delete workspace; }

rdyn_status rdyn_reset(const rdyn_model* model, rdyn_workspace* workspace, double q, double qdot,
                       rdyn_drive drive) {
  if (!model || !workspace) return RDYN_BAD_ARGUMENT;
  return to_c(rdyn::reduced::reset(model->model, workspace->ws, q, qdot, to_cpp(drive)));
}

rdyn_status rdyn_step(const rdyn_model* model, rdyn_workspace* workspace, double dt,
                      rdyn_drive drive) {
  if (!model || !workspace) return RDYN_BAD_ARGUMENT;
  return to_c(rdyn::reduced::step(model->model, workspace->ws, dt, to_cpp(drive)));
}

rdyn_status rdyn_drive_torque(const rdyn_model* model, rdyn_workspace* workspace, double q,
                              double qdot, double qddot, double* drive) {
  if (!model || !workspace || !drive) return RDYN_BAD_ARGUMENT;
  return to_c(rdyn::reduced::calc_drive_torque(model->model, workspace->ws, q, qdot, qddot, *drive));
}

rdyn_status rdyn_get_state(const rdyn_workspace* workspace, rdyn_state* state) {
  if (!workspace || !state) return RDYN_BAD_ARGUMENT;
  const auto& w = workspace->ws;
  *state = {w.get_t(), w.get_q(), w.get_qdot(), w.get_qddot(), w.get_work(), w.get_energy()};
  return RDYN_OK;
}

rdyn_status rdyn_get_forces(const rdyn_workspace* workspace, double* forces, int n) {
  if (!workspace || n < 0 || (n > 0 && !forces)) return RDYN_BAD_ARGUMENT;
  const auto& f = workspace->ws.get_forces();
  for (int k = 0; k < n && k < static_cast<int>(f.size()); ++k) forces[k] = f[k];
  return RDYN_OK;
}

const char* rdyn_workspace_message(const rdyn_workspace* workspace, int status) {
  if (workspace && (status == RDYN_BAD_DRIVE || status == RDYN_BAD_STATE))
    return workspace->ws.describe(static_cast<Status>(status));
  return rdyn_status_string(status);
}

rdyn_status rdyn_get_joint_outputs(const rdyn_workspace* workspace, double* out, int n) {
  if (!workspace || n < 0 || (n > 0 && !out)) return RDYN_BAD_ARGUMENT;
  const auto& v = workspace->ws.get_joint_outputs();
  for (int k = 0; k < n && k < static_cast<int>(v.size()); ++k) out[k] = v[k];
  return RDYN_OK;
}

}  // extern "C"
