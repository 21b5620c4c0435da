#pragma once
// A small deterministic RunRecord shared by the run-file round-trip test and the helper
// program whose output test_run_file_h5py.py reads. Every number is a dyadic rational, so
// the Python check can recompute it exactly; keep the formulas in step with that script.
#include <string>

#include "common/config.hpp"
#include "common/profile.hpp"

namespace shaker::testing {

inline constexpr std::size_t sample_phases = 3, sample_bins = 5;

inline RunRecord make_sample_record(bool with_standard_errors) {
  RunRecord record;
  record.solver = "synthetic";
  record.model_variant = "constant e; paper transport";
  config::Config config;
  config.set("material.e=0.8");
  config.set("case.name=sample run");
  record.configuration = config.to_toml();
  record.e = 0.8;
  for (std::size_t k = 0; k < sample_phases; ++k) {
    const double kk = static_cast<double>(k);
    Profile p;
    p.time = 10.0 + 0.25 * kk;
    p.phase = 0.25 * kk;
    p.plate_z = 1.5 * kk;
    p.plate_v = -0.5 * kk;
    p.bin_height = 0.5;
    for (std::size_t i = 0; i < sample_bins; ++i) {
      const double ii = static_cast<double>(i);
      p.z.push_back(0.5 * ii + 0.25);
      p.n.push_back(0.125 * (ii + 1.0) + kk);
      p.nu.push_back(0.0625 * (ii + 1.0) + 0.125 * kk);
      p.uz.push_back(-0.75 * ii + kk);
      p.T.push_back(0.0625 * (ii + 1.0) * (kk + 1.0));
      if (with_standard_errors) {
        p.samples.push_back(16.0 * ii + kk);
        p.n_se.push_back(0.03125 * (ii + 1.0));
        p.uz_se.push_back(0.015625 * (ii + kk));
        p.T_se.push_back(0.25 * ii);
      }
    }
    record.profiles.push_back(p);
  }
  // The columns docs/output-schema.md says are always present.
  record.series.add("t", {0.0, 0.5, 1.0, 1.5});
  record.series.add("phase", {0.0, 0.0475, 0.095, 0.1425});
  record.series.add("plate_z", {0.0, -0.25, 0.5, 0.125});
  record.series.add("com_z", {4.5, 4.75, 5.0, 5.25});
  return record;
}

}  // namespace shaker::testing
