#include "validate/analysis/calibrate_on_table.hpp"

#include <utility>

namespace rdyn::validate {

CalibrationResult calibrate_on_table(CalibrationTable& table, const models::Scene& table_scene,
                                     const models::Scene& case_scene, const CalibrationOptions& opt,
                                     Progress& progress) {
  // The scene first: an argument evaluated after the table's move could throw it away.
  const models::Scene unit = with_unit_load(table_scene, opt);
  reduced::ReducedModel m = reduced::make_reduced_model(table.samples, unit, std::move(table.table));
  // The rvalue overload calibrates m in place (its loads and coefficients change, its table
  // does not) and leaves it here: the table goes back to the caller either way.
  struct GiveBack {
    CalibrationTable& to;
    reduced::ReducedModel& from;
    ~GiveBack() { to.table = std::move(from.table); }
  } give_back{table, m};
  return calibrate_reduced(std::move(m), case_scene, opt, progress);
}

}  // namespace rdyn::validate
