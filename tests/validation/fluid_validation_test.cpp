// The fluid against Lobovsky et al.'s (2014) dam-break experiment (bench/reference/
// lobovsky2014_sensor1.csv, _sensor3.csv): the impact times at pressure sensors 1 and 3, the
// pressure plateaus after the impact and the water level at gauge H1, at dp = H/40
// (bench/studies/fluid_dambreak_impact.yaml goes to H/80); and the transient Poiseuille flow
// against its series solution; the Taylor-Green vortex against its analytic decay, with and
// without the transport-velocity shift; vortex shedding behind a cylinder at Re = 100.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

struct Series {
  std::vector<double> t, value;
};

Series read_probe(const std::string& file, int column) {
  return {test::csv_column(file, 0), test::csv_column(file, column)};
}

Series read_experiment(const std::string& file = "lobovsky2014_sensor1.csv") {
  Series s;
  std::ifstream in(std::string(COSPH_SOURCE_DIR) + "/bench/reference/" + file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    const auto comma = line.find(',');
    s.t.push_back(std::stod(line.substr(0, comma)));
    s.value.push_back(std::stod(line.substr(comma + 1)));
  }
  return s;
}

double first_crossing(const Series& s, double threshold) {
  for (std::size_t k = 0; k < s.t.size(); ++k)
    if (s.value[k] >= threshold) return s.t[k];
  return NAN;
}

double mean_over(const Series& s, double from, double to) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < s.t.size(); ++k)
    if (s.t[k] >= from && s.t[k] <= to && std::isfinite(s.value[k])) {
      sum += s.value[k];
      ++n;
    }
  return n ? sum / n : NAN;
}

// The mean of a - b over a's samples in [from, to], b interpolated linearly at a's times.
double mean_difference_over(const Series& a, const Series& b, double from, double to) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < a.t.size(); ++k) {
    if (a.t[k] < from || a.t[k] > to || !std::isfinite(a.value[k])) continue;
    const auto upper = std::lower_bound(b.t.begin(), b.t.end(), a.t[k]);
    if (upper == b.t.begin() || upper == b.t.end()) continue;
    const std::size_t j = upper - b.t.begin();
    const double w = (a.t[k] - b.t[j - 1]) / (b.t[j] - b.t[j - 1]);
    sum += a.value[k] - ((1.0 - w) * b.value[j - 1] + w * b.value[j]);
    ++n;
  }
  return n ? sum / n : NAN;
}

// Runs the 2D dam break (examples/fluid_dambreak_2d.yaml) at its H/40 to t = 6, the sensors
// sampled every 0.005, with `overrides` on top; returns its output directory.
std::string run_dam_break(const std::string& name, std::vector<std::string> overrides) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + name;
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_dambreak_2d.yaml";
  for (const char* o :
       {"end_time=6", "output.interval=6", "probes[0].interval=0.005", "probes[1].interval=0.005"})
    overrides.push_back(o);
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  return options.output_directory;
}

// Both probes read the sensors: `wall_pressure` (the water's pressure interpolated at the sensor's
// centre) and `sensors` (the mean pressure over the sensor's face from the water's force on the
// wall behind it, what a transducer measures).
TEST(FluidValidation, DamBreakImpactAndPlateauAtSensorsOneAndThreeMatchTheExperiment) {
  const std::string directory = run_dam_break("cosph_fluid_dambreak", {});
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const std::string point_file = directory + "/wall_pressure.csv";
  const std::string face_file = directory + "/sensors.csv";
  const Series point1 = read_probe(point_file, 1), face1 = read_probe(face_file, 1);
  const Series point3 = read_probe(point_file, 3), face3 = read_probe(face_file, 3);
  const Series experiment = read_experiment();
  const Series experiment3 = read_experiment("lobovsky2014_sensor3.csv");
  const double measured = first_crossing(experiment, 0.5),
               measured3 = first_crossing(experiment3, 0.5);
  const double impact = first_crossing(face1, 0.5), impact_point = first_crossing(point1, 0.5);
  const double impact3 = first_crossing(face3, 0.5), impact3_point = first_crossing(point3, 0.5);
  const double plateau = mean_over(face1, 3.5, 5.5), expected = mean_over(experiment, 3.5, 5.5);
  const double plateau3 = mean_over(face3, 3.5, 5.5), expected3 = mean_over(experiment3, 3.5, 5.5);
  std::cout << "sensor 1: impact at " << impact << " (point probe " << impact_point
            << "; experiment " << measured << "), plateau p/(rho g H) " << plateau
            << " (point probe " << mean_over(point1, 3.5, 5.5) << "; experiment " << expected
            << ")\n";
  std::cout << "sensor 3: impact at " << impact3 << " (point probe " << impact3_point
            << "; experiment " << measured3 << "), plateau " << plateau3 << " (point probe "
            << mean_over(point3, 3.5, 5.5) << "; experiment " << expected3 << ")\n";
  // Measured at H/40 (first samples past 0.5, every 0.005): sensor 1's impact 0.0006 late by both
  // probes (within one sample; bounded at one and a half samples); sensor 3's 0.035 early by the
  // wall sensor, 0.076 by the point probe.
  EXPECT_NEAR(impact, measured, 1.5 * 0.005);
  EXPECT_NEAR(impact_point, measured, 1.5 * 0.005);
  EXPECT_NEAR(impact3, measured3, 1.5 * 0.035);
  EXPECT_NEAR(impact3_point, measured3, 1.5 * 0.076);
  // The plateaus (wall sensors, the walls' force averaged over each step): 0.790 (+17.8%) and
  // 0.653 (+10.9%; the point probes read 0.982 and 0.816). The last acoustic sub-step's force
  // alone read 0.734 (+9.5%) and 0.654. The run-up jet's weight and the water turning at the
  // corner load the wall's foot; the single-phase scheme converges above the experiment
  // (bench/studies/fluid_dambreak_plateau.yaml). Sensor 1's face is the wall's lowest column,
  // which takes the push on the corner's particles (WallSensor; at rest in a tank the corner's
  // share is 23%). With the dissipation along the normal as each fluid particle sees it, the
  // surge came 0.036 early; with the wall friction of the earlier scheme 0.26 late.
  EXPECT_NEAR(plateau, expected, 1.5 * 0.119);
  EXPECT_NEAR(plateau3, expected3, 1.5 * 0.064);

  // The water level at gauge H1 (x = H), every time unit until the reflected wave returns.
  const Series gauge = read_probe(directory + "/gauge_H1.csv", 1);
  const Series level = read_experiment("lobovsky2014_gauge_H1.csv");
  // Measured -0.0135, -0.0055, -0.0015, -0.0042 H at t = 1, 2, 3, 4; each bounded at 1.5x, but
  // not below 0.004 H (a sixth of the H/40 spacing) where the two curves happen to cross.
  const std::map<double, double> bound = {{1.0, 0.020}, {2.0, 0.0083}, {3.0, 0.004}, {4.0, 0.0063}};
  for (const auto& [t, allowed] : bound) {
    auto at = [t](const Series& s) {
      std::size_t k = 0;
      while (k + 1 < s.t.size() && s.t[k + 1] <= t) ++k;
      return s.value[k];
    };
    std::cout << "gauge H1 at t = " << t << ": " << at(gauge) << " (experiment " << at(level)
              << ")\n";
    EXPECT_NEAR(at(gauge), at(level), allowed) << "gauge H1 at t = " << t;
  }
}

// The standard deviation of a series around its centred moving mean over `width`, over
// [from, to]: the noise study's measure (bench/study.py, kind noise). The mean is taken over
// round(width / spacing) samples made odd (at the samples' median spacing), the ends repeating
// the first and last sample. NaN where the mean would span fewer than three samples or no sample
// lies in [from, to].
double noise_over(const Series& s, double width, double from, double to) {
  if (s.t.size() < 3) return NAN;
  std::vector<double> gaps;
  for (std::size_t k = 1; k < s.t.size(); ++k) gaps.push_back(s.t[k] - s.t[k - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  const int half = static_cast<int>(std::lround(width / gaps[gaps.size() / 2])) / 2;
  if (half < 1) return NAN;
  const int n = static_cast<int>(s.t.size());
  double sum = 0.0, square = 0.0;
  int count = 0;
  for (int k = 0; k < n; ++k) {
    if (s.t[k] < from || s.t[k] > to) continue;
    double mean = 0.0;
    for (int j = k - half; j <= k + half; ++j) mean += s.value[std::clamp(j, 0, n - 1)];
    const double d = s.value[k] - mean / double(2 * half + 1);
    sum += d, square += d * d, ++count;
  }
  if (count == 0) return NAN;
  return std::sqrt(square / count - (sum / count) * (sum / count));
}

// The same run with the free-surface transport-velocity shift (one sweep per step; the particles
// under 0.95 of a full number density, or within two spacings' hydrostatic head of the surface,
// left): the wall layer keeps sum_j V_j grad W_ij near zero and the wall's force carries the
// water's pressure. Measured on this run (output every 6, one draw of the chaotic flow): sensor 1's
// noise (around its 20 ms moving mean over t = 3.5-5.5) 0.0430 against 0.1024 unshifted (the noise
// study's five runs: 0.040-0.051); its plateau 0.8984 (the five runs' mean 0.9020, members
// 0.8962-0.9066); the impact 0.0087 late. The level at gauge H2 over t = 2-5.5 stands 0.0242 H
// above the experiment's (the studies' six runs at H/40: 0.0239-0.0244): the band holds the
// layer under the surface (without the band 0.0299, unshifted 0.0213).
TEST(FluidValidation, DamBreakWithTheFreeSurfaceShiftCutsTheWallPressureNoise) {
  const std::string directory = run_dam_break(
      "cosph_fluid_dambreak_shift",
      {"modules[0].fluid.transport_velocity=true", "modules[0].fluid.transport_velocity_sweeps=1",
       "modules[0].fluid.transport_velocity_free_surface=0.95",
       "modules[0].fluid.transport_velocity_hydrostatic_band=2"});
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const Series face1 = read_probe(directory + "/sensors.csv", 1);
  const double noise = noise_over(face1, 0.1144, 3.5, 5.5);
  const double plateau = mean_over(face1, 3.5, 5.5);
  const double impact = first_crossing(face1, 0.5);
  const double level = mean_difference_over(read_probe(directory + "/gauge_H2.csv", 1),
                                            read_experiment("lobovsky2014_gauge_H2.csv"), 2.0, 5.5);
  std::cout << "shifted: sensor 1 noise " << noise << " (unshifted 0.1024), plateau " << plateau
            << " (five runs at H/40: 0.9020), impact " << impact << "; gauge H2 " << level
            << " H above the experiment (unshifted +0.0213)\n";
  EXPECT_LT(noise, 1.5 * 0.0430);  // 0.0645: the unshifted run's 0.1024 fails it
  // Measured 0.8984; the members lie within 0.0058 of their mean.
  EXPECT_NEAR(plateau, 0.9020, 1.5 * 0.0058);
  EXPECT_NEAR(impact, first_crossing(read_experiment(), 0.5), 1.5 * 0.0087);  // measured 0.0087
  // Measured 0.0242. The level is what the band changes, by 0.0057 H, ten times the six runs'
  // spread (0.0005), so it is bounded at half that change: the shift without the band (0.0299)
  // fails, and so would a band that held the bulk too (unshifted, 0.0213).
  EXPECT_NEAR(level, 0.0242, 0.5 * (0.0299 - 0.0242));
}

// Transient Poiseuille flow between no-slip plates (examples/fluid_poiseuille.yaml): the series
// solution with g = 0.8, nu = 0.1, L = 1.
double poiseuille(double y, double t) {
  const double g = 0.8, nu = 0.1, pi = 3.14159265358979323846;
  double u = g * y * (1.0 - y) / (2.0 * nu);
  for (int n = 0; n < 100; ++n) {
    const double m = 2 * n + 1;
    u -= 4.0 * g / (nu * pi * pi * pi * m * m * m) * std::sin(m * pi * y) *
         std::exp(-m * m * pi * pi * nu * t);
  }
  return u;
}

TEST(FluidValidation, PoiseuilleFlowFollowsTheAnalyticTransient) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_fluid_poiseuille";
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_poiseuille.yaml";
  Simulation simulation(load_scene_file(scene, {"output.interval=2"}), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const Series centre = read_probe(options.output_directory + "/centre.csv", 1);
  double worst = 0.0;
  for (std::size_t k = 0; k < centre.t.size(); ++k) {
    if (centre.t[k] < 0.2) continue;  // relative errors of the first, tiny velocities
    const double expected = poiseuille(0.5, centre.t[k]);
    worst = std::max(worst, std::abs(centre.value[k] - expected) / expected);
  }
  // The profile across the channel at the end (20 points from y = 0.025 to 0.975).
  double diff = 0.0, norm = 0.0;
  for (int k = 1; k <= 20; ++k) {
    const Series profile = read_probe(options.output_directory + "/profile.csv", k);
    const double y = 0.025 + 0.95 * (k - 1) / 19.0;
    const double expected = poiseuille(y, profile.t.back());
    diff += (profile.value.back() - expected) * (profile.value.back() - expected);
    norm += expected * expected;
  }
  std::cout << "Poiseuille: centre-line velocity within " << worst
            << " of the analytic transient; final profile relative L2 " << std::sqrt(diff / norm)
            << "\n";
  EXPECT_LT(worst, 1.5 * 0.00417);                   // measured 0.417%
  EXPECT_LT(std::sqrt(diff / norm), 1.5 * 0.00478);  // measured 0.478% (linear probe)
}

// Relative L2 error of the Taylor-Green kinetic energy 0.25 exp(-16 pi^2 nu t) up to t_end.
struct TaylorGreenRun {
  double l2_error, final_ratio;
};

TaylorGreenRun run_taylor_green(const std::string& name, std::vector<std::string> overrides,
                                double end_time) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + name;
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_taylor_green.yaml";
  overrides.push_back("end_time=" + std::to_string(end_time));
  overrides.push_back("output.vtp=false");
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  if (test::reduced_run()) return {NAN, NAN};
  const Series energy = read_probe(options.output_directory + "/kinetic_energy.csv", 1);
  const double nu = 0.01, pi = std::acos(-1.0);
  auto analytic = [&](double t) { return 0.25 * std::exp(-16.0 * pi * pi * nu * t); };
  double diff = 0.0, norm = 0.0;
  for (std::size_t k = 0; k < energy.t.size(); ++k) {
    const double e = analytic(energy.t[k]);
    diff += (energy.value[k] - e) * (energy.value[k] - e);
    norm += e * e;
  }
  return {std::sqrt(diff / norm), energy.value.back() / analytic(energy.t.back())};
}

// 50 x 50 particles start on a lattice that the flow stretches at the stagnation points; eight
// sweeps of the transport-velocity shift keep the distribution isotropic and the decay close to
// the analytic one (bench/studies/fluid_taylor_green.yaml: 1.3% at 100 x 100).
TEST(FluidValidation, TaylorGreenVortexDecaysAtTheAnalyticRate) {
  const TaylorGreenRun run = run_taylor_green("cosph_fluid_taylor_green", {}, 1.0);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout << "Taylor-Green, 8 sweeps: kinetic energy relative L2 " << run.l2_error
            << ", final / analytic " << run.final_ratio << "\n";
  EXPECT_LT(run.l2_error, 1.5 * 0.0504392);           // measured 0.0504392
  EXPECT_NEAR(run.final_ratio, 1.0, 1.5 * 0.069943);  // measured 0.930057
}

// Without the shift the lattice holds until the stagnation-point strain buckles it (t ~ 0.15):
// until then the scheme itself follows the analytic decay. A single sweep per step does not
// prevent the buckling (bench/studies/fluid_taylor_green.yaml).
TEST(FluidValidation, TaylorGreenWithoutTransportVelocityFollowsTheDecayUntilTheLatticeBuckles) {
  const TaylorGreenRun run = run_taylor_green("cosph_fluid_taylor_green_plain",
                                              {"modules[0].fluid.transport_velocity=false"}, 0.1);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout << "Taylor-Green, no transport velocity, t <= 0.1: relative L2 " << run.l2_error
            << ", final / analytic " << run.final_ratio << "\n";
  EXPECT_LT(run.l2_error, 1.5 * 0.0099);            // measured 0.0099
  EXPECT_NEAR(run.final_ratio, 1.0, 1.5 * 0.0247);  // measured 0.975262
}

// Channel flow past a cylinder at Re = 100 (Schaefer & Turek 2D-2) at D/10, through an inflow
// buffer and an outflow plane: the vortex street's frequency, the mean drag and the lift
// amplitude over t = 4-6, when the shedding has settled. The lift carries acoustic noise, so its
// frequency and amplitude are those of the strongest sinusoid (a scan of the Fourier projection
// over 1-6 Hz). bench/studies/fluid_cylinder_*.yaml (t = 4-7), D/20: St 0.293, C_D 3.66, C_L 1.08.
TEST(FluidValidation, CylinderSheddingAtRe100MatchesTheBenchmark) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_fluid_cylinder";
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_cylinder_re100.yaml";
  Simulation simulation(load_scene_file(scene, {"end_time=6", "output.vtp=false"}),
                        builtin_modules(), test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const std::string file = options.output_directory + "/cylinder_force.csv";
  const auto t = test::csv_column(file, 0), fx = test::csv_column(file, 1),
             fy = test::csv_column(file, 2);
  std::vector<double> time, drag, lift;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 4.0) {
      time.push_back(t[k]);
      drag.push_back(20.0 * fx[k]);  // C = 2 F / (rho U^2 D), U = 1, D = 0.1
      lift.push_back(20.0 * fy[k]);
    }
  std::cout << time.size() << " force samples over t = 4-6\n";
  ASSERT_EQ(time.size(), 401u);  // every 0.005 over [4, 6]: a structural check
  double mean_drag = 0.0, mean_lift = 0.0;
  for (std::size_t k = 0; k < time.size(); ++k) {
    mean_drag += drag[k] / time.size();
    mean_lift += lift[k] / time.size();
  }
  const double pi = std::acos(-1.0);
  double best_f = 0.0, best_amplitude = 0.0;
  for (double f = 1.0; f <= 6.0; f += 0.005) {
    double c = 0.0, s = 0.0;
    for (std::size_t k = 0; k < time.size(); ++k) {
      c += (lift[k] - mean_lift) * std::cos(2.0 * pi * f * time[k]);
      s += (lift[k] - mean_lift) * std::sin(2.0 * pi * f * time[k]);
    }
    const double amplitude = 2.0 * std::hypot(c, s) / time.size();
    if (amplitude > best_amplitude) best_f = f, best_amplitude = amplitude;
  }
  const double strouhal = best_f * 0.1;
  std::cout << "cylinder, D/10: St " << strouhal << " (0.295-0.305), mean C_D " << mean_drag
            << " (largest 3.22-3.24), C_L amplitude " << best_amplitude << " (0.99-1.01)\n";
  // D/10 is coarse: St 9% low, the drag 30% high and the lift amplitude 40% low against the
  // benchmark, each nearer it at D/20 (the study: 0.293, 3.66, 1.08). Bounded on
  // both sides around the measured values: St 0.273, mean C_D 4.19498 (against the published
  // largest value; the drag varies by ~1% over a cycle), C_L amplitude 0.597367. The force is
  // the walls' output, the mean over each step's acoustic sub-steps; the last sub-step's force
  // alone read C_D 3.456, 7% high, though the fluid received the same impulse.
  EXPECT_GT(strouhal, 0.262);
  EXPECT_LT(strouhal, 0.280);
  EXPECT_GT(mean_drag, 4.09);
  EXPECT_LT(mean_drag, 4.30);
  EXPECT_GT(best_amplitude, 0.55);
  EXPECT_LT(best_amplitude, 0.64);
}

}  // namespace
}  // namespace cosph
