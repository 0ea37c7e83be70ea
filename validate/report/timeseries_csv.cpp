#include "validate/report/timeseries_csv.hpp"

#include <cmath>

#include <fmt/format.h>

#include "models/scene.hpp"
#include "validate/io/output_dir.hpp"

namespace rdyn::validate {

void write_timeseries_csv(const std::string& path, const engine::TimeSeries& ts) {
  // No NaN in an output (issue #9): a non-finite value is a numerical failure, not a row.
  auto finite = [&](double x, size_t i, const char* what) {
    if (!std::isfinite(x))
      throw models::NumericalError(fmt::format("the time series has a non-finite {} at t = {:.6g} s", what, ts.t[i]));
  };
  TextSink sink(path);
  std::string header;  // names are checked by the scene reader
  for (const auto& n : models::timeseries_column_names(ts)) header += (header.empty() ? "" : ",") + n;
  sink.add(header + "\n");
  std::string row;
  for (size_t i = 0; i < ts.t.size(); ++i) {
    finite(ts.q[i], i, "q");
    finite(ts.qdot[i], i, "qdot");
    finite(ts.qddot[i], i, "qddot");
    finite(ts.energy[i], i, "energy");
    finite(ts.work[i], i, "work");
    row = fmt::format("{:.10g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", ts.t[i], ts.q[i], ts.qdot[i], ts.qddot[i],
                      ts.energy[i], ts.work[i]);
    for (size_t c = 0; c < ts.forces.size(); ++c) {
      finite(ts.forces[c][i], i, ("force " + ts.force_names[c]).c_str());
      row += fmt::format(",{:.17g}", ts.forces[c][i]);
    }
    for (size_t c = 0; c < ts.columns.size(); ++c) {
      finite(ts.columns[c][i], i, ts.column_names[c].c_str());
      row += fmt::format(",{:.17g}", ts.columns[c][i]);
    }
    row += '\n';
    sink.add(row);
  }
  sink.close();
}

}  // namespace rdyn::validate
