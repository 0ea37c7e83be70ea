// libFuzzer target for the reduced-table reader: any input must either parse into samples that
// build a table, or raise TableError — never crash, hang, allocate without bound, or trip a
// sanitizer. Build and run (README):
//   cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DRDYN_FUZZ=ON
//   cmake --build build-fuzz --target rdyn_fuzz_table
//   ./build-fuzz/rdyn_fuzz_table -max_total_time=600 -max_len=8192 build-fuzz/table_corpus tests/fuzz/table_corpus
#include <cstddef>
#include <cstdint>
#include <string>

#include "reduced/samples.hpp"
#include "reduced/table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto samples = rdyn::reduced::parse_samples_csv(text, "fuzz.csv");
    // What the reader accepts must be a table the interpolation can build.
    rdyn::reduced::build_table(samples, rdyn::reduced::Interpolation::CubicSpline);
    rdyn::reduced::build_table(samples, rdyn::reduced::Interpolation::Linear);
  } catch (const rdyn::reduced::TableError&) {
    // Refused with a message: the expected outcome for bad input.
  }
  return 0;
}
