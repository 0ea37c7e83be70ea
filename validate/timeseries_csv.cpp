#include "validate/timeseries_csv.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "validate/output_dir.hpp"

namespace rdyn::validate {

void write_timeseries_csv(const std::string& path, const engine::TimeSeries& ts) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw OutputError(path + ": cannot open for writing");
  std::string header = "t,q,qdot,qddot,energy,work";
  for (const auto& n : ts.force_names) header += ",F_" + n;
  fmt::print(f, "{}\n", header);
  for (size_t i = 0; i < ts.t.size(); ++i) {
    fmt::print(f, "{:.10g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", ts.t[i], ts.q[i], ts.qdot[i], ts.qddot[i],
               ts.energy[i], ts.work[i]);
    for (const auto& col : ts.forces) fmt::print(f, ",{:.17g}", col[i]);
    std::fputc('\n', f);
  }
  if (std::fclose(f) != 0) throw OutputError(path + ": write failed");
}

}  // namespace rdyn::validate
