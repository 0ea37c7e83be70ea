// Reduced parameters sampled on a grid of the independent coordinate: named columns,
// one value per grid point. This is what `rdyn extract` writes and reads back.
//
// Columns (k: requested constraint force, j: joint, b: body with a resistance):
//   m1, m2                 Eksergian: m1 q̈ + m2 q̇² = F*            [kg·m² or kg], [same]
//   me1_<k>, me2_<k>       constraint line: me1 q̈ + me2 q̇² = F*_x   [kg·m or kg], ...
//   Q_cons                 generalized force of gravity and springs on q
//   V                      their potential energy [J]
//   Qx_cons_<k>            generalized force of gravity and springs along x_k [N]
//   r_<j>                  joint rate per unit q̇ (x fixed)
//   rx_<k>_<j>             joint rate per unit ẋ_k (q̇ = 0)
//   w_<b>, wx_<k>_<b>      body angular rate per unit q̇, per unit ẋ_k
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace rdyn::reduced {

class TableError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Samples {
  std::string scene;         // scene name it was extracted from
  std::string method;        // extraction method
  bool periodic = true;      // one period 2π of a revolute coordinate
  bool revolute = true;      // q in radians (q_deg column) or metres (q_m)
  double q0 = 0.0;           // first grid point [rad or m]
  double step = 0.0;         // grid step [rad or m]
  std::vector<double> q;     // grid points (periodic: the end point 2π is not repeated)
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[c][i]
  // Exact zeros of some ratio columns within the table's span, located on the full model
  // (the switch angles of rate-gated loads): column name → sorted roots [rad or m].
  std::vector<std::pair<std::string, std::vector<double>>> roots;
  // Grid points at singular configurations, whose values were replaced by interpolation
  // through the regular samples of the same branch [rad or m].
  std::vector<double> singular_q;
  const std::vector<double>* roots_of(const std::string& column) const;  // null when absent

  int column(const std::string& name) const;  // −1 when absent
  int require(const std::string& name) const;  // throws TableError when absent
  void add(const std::string& name, std::vector<double> values);
};

// CSV with a comment line of metadata, then q_deg (or q_m) and the named columns.
void write_samples_csv(const std::string& path, const Samples& s);
// Throws TableError naming the file (and line) on malformed content.
Samples read_samples_csv(const std::string& path);

}  // namespace rdyn::reduced
