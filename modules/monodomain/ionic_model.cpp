#include "monodomain/ionic_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cosph {

std::unique_ptr<IonicModel> make_ionic_model(const proto::IonicModelSpec& spec) {
  switch (spec.model_case()) {
    case proto::IonicModelSpec::kFitzhughNagumo:
      return std::make_unique<FitzHughNagumo>(spec.fitzhugh_nagumo());
    case proto::IonicModelSpec::kAlievPanfilov:
      return std::make_unique<AlievPanfilov>(spec.aliev_panfilov());
    case proto::IonicModelSpec::kPreset: {
      // Seed 001: table 1 (propagation, section 5.3), table 2 (spiral waves, section 5.4),
      // table 5 (biventricular heart, section 5.8). The schema defaults hold tables 1 and 2.
      if (spec.preset() == "aliev_panfilov_table1")
        return std::make_unique<AlievPanfilov>(proto::AlievPanfilovSpec());
      if (spec.preset() == "fitzhugh_nagumo_table2")
        return std::make_unique<FitzHughNagumo>(proto::FitzHughNagumoSpec());
      if (spec.preset() == "aliev_panfilov_table5") {
        proto::AlievPanfilovSpec p;
        p.set_a(0.01);
        return std::make_unique<AlievPanfilov>(p);
      }
      throw std::invalid_argument(
          "unknown ionic model preset '" + spec.preset() +
          "' (known: aliev_panfilov_table1, fitzhugh_nagumo_table2, aliev_panfilov_table5)");
    }
    case proto::IonicModelSpec::MODEL_NOT_SET:
      break;
  }
  throw std::invalid_argument(
      "an ionic model needs one of: fitzhugh_nagumo, aliev_panfilov, preset");
}

double reaction_step_limit(const IonicModel& model) {
  double steepest = 0.0;
  const int samples = 200;
  const double dv = 1e-6;
  for (int k = 0; k <= samples; ++k) {
    const double V = double(k) / samples;
    const double slope =
        (model.voltage(V + dv, 0.0).production - model.voltage(V - dv, 0.0).production) / (2 * dv);
    steepest = std::max(steepest, std::abs(slope));
  }
  return steepest > 0.0 ? 1.0 / steepest : INFINITY;
}

}  // namespace cosph
