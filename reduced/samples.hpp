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
//   tau_<load>             a profiled load's τ(θ_of(q)) per unit amplitude
//   Qpf_<f>, Qxpf_<k>_<f>  point force f: generalized force per unit tension on q (−dL/dq) and
//                          along x_k (−dL/dx_k)
#pragma once

#include <cstdint>
#include <optional>
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
  // models::scene_hash of the scene it was extracted from; make_reduced_model refuses a
  // scene with another hash. Empty only for samples assembled by hand.
  std::optional<std::uint64_t> scene_hash;
  std::string file;          // the file it was read from (for messages); empty when extracted
  // Read from a file whose content checksum matched (format_samples_csv writes one); false for a
  // table written before checksums (its edits cannot be detected) and for extracted samples.
  bool content_checked = false;
  long header_line = 0;      // line of the column header in `file` (for messages); 0 when extracted
  std::string method;        // extraction method
  bool periodic = true;      // one period 2π of a revolute coordinate
  bool revolute = true;      // q in radians (q_deg column) or metres (q_m)
  double q0 = 0.0;           // first grid point [rad or m]
  double step = 0.0;         // grid step [rad or m]
  std::vector<double> q;     // grid points (periodic: the end point 2π is not repeated)
  // Range tables (periodic = false): what ends the range at q.front() and q.back(), "dead point"
  // or "declared limit" (metadata edges=<min>,<max>, spaces as '-'); empty when unknown.
  std::string min_edge, max_edge;
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[c][i]
  // Exact zeros of some ratio columns within the table's span, located on the full model
  // (the switch angles of rate-gated loads): column name → sorted roots [rad or m].
  std::vector<std::pair<std::string, std::vector<double>>> roots;
  // Grid points at singular configurations, whose values were replaced by interpolation
  // through the regular samples of the same branch [rad or m].
  std::vector<double> singular_q;
  // Constraint forces whose columns have a simple pole at some of those points (the constraint
  // actuator's rates diverge there; sweep_refine.hpp, is_simple_pole): force name → sorted q
  // [rad or m]. No interpolation represents them there; the reduced model refuses the force's
  // rows near them (reduced_model.hpp, check_force_poles).
  std::vector<std::pair<std::string, std::vector<double>>> poles;
  // The smallest loop conditioning over the grid samples (1 when the source gives none; not
  // written to the table).
  double min_conditioning = 1.0;
  const std::vector<double>* roots_of(const std::string& column) const;  // null when absent

  int column(const std::string& name) const;  // −1 when absent
  int require(const std::string& name) const;  // throws TableError (file and header line) when absent
  void add(const std::string& name, std::vector<double> values);
};

// `s` with only the columns `keep` names, in s's order (a name s lacks is skipped: whoever needs
// it then gets require's message), and the roots of the kept columns; the grid and everything
// else as in s. Each interpolant fits every column on its own, so a table built from the result
// has, column for column, the values of the table of s (bit for bit; energy_consistent_m2 also
// reads m1 and V, so keep them with m2 and Q_cons). A sweep fits only what its cases read.
Samples select_columns(const Samples& s, const std::vector<std::string>& keep);

// Limits on a table that is read (what `rdyn extract` can write, with margin): a grid of at
// most 36 001 points (0.01° over a turn, the finest extraction grid), at most 4096 columns,
// 2·10⁷ values and 256 MiB of text.
inline constexpr long kMaxTableRows = 36001;
inline constexpr long kMaxTableColumns = 4096;
inline constexpr long kMaxTableValues = 20000000;
inline constexpr long kMaxTableBytes = 256L << 20;

// CSV: a first comment line
//   # rdyn-table v1 scene=<16 hex digits> name=<scene> method=<m> periodic=<0|1> q0=<q> step=<h> grid_deg=<deg>
// (q0 and step in rad or m, %.17g; range tables add edges=<min>,<max>: dead-point or declared-limit), optional "# singular:" and "# roots <column>:" lines, then
// q_deg (or q_m) and the named columns. Requires samples.scene_hash.
// The table as text (header line with the scene hash, metadata comments, CSV).
std::string format_samples_csv(const Samples& s);
void write_samples_csv(const std::string& path, const Samples& s);
// Parses the text of a table; `name` is used in messages. Throws TableError naming the file,
// line and field on malformed content: a content checksum that does not match (an edited table),
// a missing or older header (re-extract), values that are
// not finite, a grid that is not increasing and uniform, duplicate or unknown column names,
// ragged rows, an m1 that is not positive, or a table over the limits above.
Samples parse_samples_csv(const std::string& text, const std::string& name);
// Reads a file (refusing one over kMaxTableBytes before reading it) and parses it.
Samples read_samples_csv(const std::string& path);

}  // namespace rdyn::reduced
