// Stability suite for the solid module: the Land et al. (2015) ventricle with nu = 0.495 inflated
// to 10 kPa comes to rest (no ringing, no tangling) keeping its volume, and a column twisted by a
// large initial angular velocity turns for several torsional periods keeping its energy (without
// artificial viscosity) or losing what the artificial viscosity dissipates (with it). The health
// monitor (finite fields, J > 0) runs every 100 steps; a violation throws.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

std::string example(const std::string& name) {
  return std::string(COSPH_SOURCE_DIR) + "/examples/" + name;
}

using test::csv_column;

template <typename Check>
void run(const std::string& scene, const std::vector<std::string>& overrides,
         const std::string& tag, const Check& check) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_solid_stability_" + tag;
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  simulation.run();  // throws HealthError on NaN or J <= 0
  COSPH_SKIP_CHECKS_IF_REDUCED();
  BodyViews views;
  simulation.module(0).bodies(views);
  check(*views.bodies3.at(0).particles, options.output_directory);
}

// Measured at the example's 1 mm (3,196 particles): J in [0.948561, 1.06544] (the extremes sit
// at the clamped base's rim), the wall's deformed volume sum J V0 / sum V0 = 0.999519, final
// kinetic energy 2.54e-29 J, 1.54e-24 of its peak 1.648e-5 J, the endocardial apex at z = -24.0746
// mm (issue 13 studies how it converges; here it guards the value).
TEST(SolidStability, NearlyIncompressibleVentricleComesToRest) {
  run(example("solid_land_ventricle.yaml"), {"output.interval=0.25"}, "ventricle",
      [](const ParticleSet<3>& p, const std::string& dir) {
        const auto& J = p.scalar("J");
        const auto& V0 = p.scalar("volume");
        double lo = INFINITY, hi = -INFINITY, deformed = 0.0, reference = 0.0;
        for (std::size_t i = 0; i < J.size(); ++i) {
          lo = std::min(lo, J[i]);
          hi = std::max(hi, J[i]);
          deformed += J[i] * V0[i];
          reference += V0[i];
        }
        std::cout << std::setprecision(6) << "J in [" << lo << ", " << hi << "], wall volume "
                  << deformed / reference << " of the reference\n";
        EXPECT_GT(lo, 1.0 - 1.5 * 0.0514);  // nu = 0.495: the wall keeps its volume
        EXPECT_LT(hi, 1.0 + 1.5 * 0.0654);
        EXPECT_NEAR(deformed / reference, 1.0, 1.5 * 4.81e-4);  // measured 1 - 4.81e-4
        const auto kinetic = csv_column(dir + "/kinetic_energy.csv", 1);
        const double peak = *std::max_element(kinetic.begin(), kinetic.end());
        std::cout << "kinetic energy: peak " << peak << ", final " << kinetic.back() << " ("
                  << kinetic.back() / peak << " of the peak)\n";
        // At rest: no ringing left. The damped decay is exponential (24 decades over the run), so
        // the bound is on its order of magnitude: 1e-22 of the peak against the measured 1.54e-24
        // (10% less damping leaves about 150 times more).
        EXPECT_LT(kinetic.back(), 1e-22 * peak);
        const double apex = csv_column(dir + "/apex.csv", 1).back();
        std::cout << "endocardial apex z " << apex * 1e3 << " mm\n";
        // Both sides, 8% of the apex's 4.07 mm travel from -20 mm.
        EXPECT_GT(apex, -0.02440);
        EXPECT_LT(apex, -0.02375);
      });
}

// The column spun about its axis (the example: hourglass control, no artificial viscosity),
// energy measured as kinetic + strain energy. Position Verlet keeps it: measured final / initial
// 0.998247 after 2 s, never above the initial energy, the kinetic energy falling below a fifth
// of it at every extreme twist. With the default artificial viscosity (alpha 0.04, beta 0.08)
// added, 0.956857 is left: what that dissipation costs. (Without hourglass control the twist
// scatters into particle-scale modes after two twists: the kinetic energy stays near half the
// total instead of swinging; the artificial viscosity then dissipated 59% in 2 s.)
void check_twisted_column(const std::vector<std::string>& overrides, const std::string& tag,
                          double final_low, double final_high) {
  std::vector<std::string> all = {"output.interval=2"};
  all.insert(all.end(), overrides.begin(), overrides.end());
  run(example("solid_twisting_column.yaml"), all, tag,
      [&](const ParticleSet<3>& p, const std::string& dir) {
        const auto kinetic = csv_column(dir + "/kinetic_energy.csv", 1);
        const auto elastic = csv_column(dir + "/elastic_energy.csv", 1);
        ASSERT_EQ(kinetic.size(), elastic.size());
        const double initial = kinetic[0] + elastic[0];
        double highest = 0.0;
        int turns = 0;  // kinetic energy minima: the column stops at each extreme twist
        for (std::size_t k = 0; k < kinetic.size(); ++k) {
          highest = std::max(highest, kinetic[k] + elastic[k]);
          if (k > 0 && k + 1 < kinetic.size() && kinetic[k] < kinetic[k - 1] &&
              kinetic[k] < kinetic[k + 1] && kinetic[k] < 0.2 * initial)
            ++turns;
        }
        const double final_ratio = (kinetic.back() + elastic.back()) / initial;
        std::cout << std::setprecision(6) << tag << ": " << turns
                  << " extreme twists, energy max/initial " << highest / initial
                  << ", final/initial " << final_ratio << "\n";
        EXPECT_GE(turns, 10);  // several torsional half periods (measured 11)
        std::cout << tag << ": highest energy - initial " << (highest - initial) / initial
                  << " of the initial\n";
        EXPECT_LE(highest, initial);  // measured: no sample above the initial energy (excess 0)
        EXPECT_GT(final_ratio, final_low);
        EXPECT_LT(final_ratio, final_high);
        // Large rotation: the top corner moved by up to 1.439 (1.43786 with artificial
        // viscosity), more than the column's width; bounded within 5% of it.
        const auto x = csv_column(dir + "/top.csv", 1), y = csv_column(dir + "/top.csv", 2);
        double reach = 0.0;
        for (std::size_t k = 0; k < x.size(); ++k) reach = std::max(reach, std::hypot(x[k], y[k]));
        std::cout << tag << ": top corner moved by up to " << reach << "\n";
        EXPECT_GT(reach, 0.95 * 1.439);
        EXPECT_LT(reach, 1.05 * 1.439);
        const auto& J = p.scalar("J");
        std::cout << tag << ": J in [" << *std::min_element(J.begin(), J.end()) << ", "
                  << *std::max_element(J.begin(), J.end()) << "]\n";
        // Measured J in [0.960444, 1.02734] (with artificial viscosity [0.957103, 1.02479]):
        // bounded at 1.5x the larger excursions from 1.
        for (double j : J) {
          ASSERT_GT(j, 1.0 - 1.5 * (1.0 - 0.957103));
          ASSERT_LT(j, 1.0 + 1.5 * (1.02734 - 1.0));
        }
      });
}

TEST(SolidStability, TwistedColumnKeepsItsEnergyThroughLargeRotations) {
  check_twisted_column({}, "twist", 1.0 - 1.5 * (1.0 - 0.998247), 1.0001);
}

TEST(SolidStability, TwistedColumnLosesWhatArtificialViscosityDissipates) {
  check_twisted_column({"modules[0].solid.artificial_viscosity.alpha=0.04"}, "twist_viscous", 0.950,
                       0.963);  // measured 0.956857
}

}  // namespace
}  // namespace cosph
