// Ionic models and the quasi-steady-state Strang splitting (seed 001 eqs. 8, 9, 32-34).
#include "monodomain/ionic_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

namespace cosph {
namespace {

// The models' right-hand sides written out directly from seed 001 eqs. (8) and (9).
double fhn_current(const proto::FitzHughNagumoSpec& p, double V, double w) {
  return -V * (V - p.a()) * (V - 1.0) - w;
}
double fhn_gate(const proto::FitzHughNagumoSpec& p, double V, double w) {
  return p.epsilon0() * (p.beta() * V - p.gamma() * w - p.sigma());
}
double ap_current(const proto::AlievPanfilovSpec& p, double V, double w) {
  return -p.k() * V * (V - p.a()) * (V - 1.0) - w * V;
}
double ap_gate(const proto::AlievPanfilovSpec& p, double V, double w) {
  const double eps = p.epsilon0() + p.mu1() * w / (p.mu2() + V);
  return eps * (-p.k() * V * (V - p.b() - 1.0) - w);
}

TEST(IonicModel, RateSplitsReproduceTheModelRightHandSides) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uV(-0.2, 1.2), uw(0.0, 2.0);
  proto::FitzHughNagumoSpec fp;
  fp.set_sigma(0.05);
  proto::AlievPanfilovSpec ap;
  const FitzHughNagumo fhn(fp);
  const AlievPanfilov aliev(ap);
  for (int k = 0; k < 1000; ++k) {
    const double V = uV(rng), w = uw(rng);
    RateSplit r = fhn.voltage(V, w);
    EXPECT_NEAR(r.production - r.loss * V, fhn_current(fp, V, w), 1e-12);
    r = fhn.gate(V, w);
    EXPECT_NEAR(r.production - r.loss * w, fhn_gate(fp, V, w), 1e-12);
    r = aliev.voltage(V, w);
    EXPECT_NEAR(r.production - r.loss * V, ap_current(ap, V, w), 1e-12);
    EXPECT_GE(r.loss, 0.0);
    r = aliev.gate(V, w);
    EXPECT_NEAR(r.production - r.loss * w, ap_gate(ap, V, w), 1e-12);
  }
}

TEST(IonicModel, QssUpdateIsExactForFrozenRates) {
  // dy/dt = q - p y has y(t) = q/p + (y0 - q/p) e^(-p t).
  for (double p : {0.0, 1e-14, 0.3, 50.0}) {
    const double q = 0.7, y0 = 2.0, dt = 0.4;
    const double exact =
        p == 0.0 || p < 1e-13 ? y0 + q * dt : q / p + (y0 - q / p) * std::exp(-p * dt);
    EXPECT_NEAR(qss_update(y0, {q, p}, dt), exact, 1e-12) << "p = " << p;
  }
  // Unconditionally stable: a huge step lands on the equilibrium, never beyond it.
  EXPECT_NEAR(qss_update(5.0, {3.0, 1.5}, 1e6), 2.0, 1e-12);
}

TEST(IonicModel, PresetsAreTheSeedTables) {
  proto::IonicModelSpec spec;
  spec.set_preset("aliev_panfilov_table5");
  const auto table5 = make_ionic_model(spec);
  // Table 5: k = 8, a = 0.01: I(V, 0) = -8 V (V - 0.01)(V - 1).
  const RateSplit r = table5->voltage(0.5, 0.0);
  EXPECT_NEAR(r.production - r.loss * 0.5, -8.0 * 0.5 * (0.5 - 0.01) * (0.5 - 1.0), 1e-14);
  spec.set_preset("aliev_panfilov_table1");
  const RateSplit r1 = make_ionic_model(spec)->voltage(0.5, 0.0);
  EXPECT_NEAR(r1.production - r1.loss * 0.5, -8.0 * 0.5 * (0.5 - 0.15) * (0.5 - 1.0), 1e-14);
  spec.set_preset("fitzhugh_nagumo_table2");
  EXPECT_EQ(make_ionic_model(spec)->name(), "FitzHugh-Nagumo");
  spec.set_preset("luo_rudy");
  EXPECT_THROW(make_ionic_model(spec), std::invalid_argument);
}

// Single cell (no diffusion): the Strang QSS step converges to the RK4 solution. The splitting of
// the reactions is second order, but the QSS update freezes q(y) and p(y) at the start of each
// sub-step, which is a first-order approximation when they depend on y (here V^3 terms): the
// method is first order overall, as measured (ratio 2.00 per halving).
double single_cell_error(double dt) {
  const AlievPanfilov model{proto::AlievPanfilovSpec()};
  const double T = 20.0;
  auto rhs = [&](double V, double w, double& dV, double& dw) {
    RateSplit a = model.voltage(V, w), b = model.gate(V, w);
    dV = a.production - a.loss * V;
    dw = b.production - b.loss * w;
  };
  double Vr = 0.3, wr = 0.0;  // reference: RK4 with a tiny step
  const double h = 1e-4;
  for (int k = 0; k < static_cast<int>(std::round(T / h)); ++k) {
    double k1v, k1w, k2v, k2w, k3v, k3w, k4v, k4w;
    rhs(Vr, wr, k1v, k1w);
    rhs(Vr + 0.5 * h * k1v, wr + 0.5 * h * k1w, k2v, k2w);
    rhs(Vr + 0.5 * h * k2v, wr + 0.5 * h * k2w, k3v, k3w);
    rhs(Vr + h * k3v, wr + h * k3w, k4v, k4w);
    Vr += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    wr += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
  double V = 0.3, w = 0.0;
  for (int k = 0; k < static_cast<int>(std::round(T / dt)); ++k) {
    react_before_diffusion(model, V, w, 0.5 * dt);
    react_after_diffusion(model, V, w, 0.5 * dt);
  }
  return std::abs(V - Vr) + std::abs(w - wr);
}

TEST(IonicModel, StrangQssSingleCellConvergesWithFirstOrder) {
  const double e1 = single_cell_error(0.02), e2 = single_cell_error(0.01),
               e3 = single_cell_error(0.005);
  std::cout << "single-cell error: dt 0.02 " << e1 << ", 0.01 " << e2 << ", 0.005 " << e3 << "\n";
  EXPECT_GT(e1 / e2, 1.8);
  EXPECT_GT(e2 / e3, 1.8);
  EXPECT_LT(e3, 1e-3);
}

// The reaction's step limit is 1 / max |dq/dV| over V in [0, 1]: for FitzHugh-Nagumo's table 2
// the slope -3 V^2 + 2 (a + 1) V is steepest at V = 1 (|-0.8|), for Aliev-Panfilov's table 1 the
// slope k (-3 V^2 + 2 (a + 1) V) likewise (|-5.6|).
TEST(IonicModel, ReactionStepLimitIsTheInverseOfTheSteepestProductionSlope) {
  EXPECT_NEAR(reaction_step_limit(FitzHughNagumo(proto::FitzHughNagumoSpec())), 1.0 / 0.8, 1e-6);
  EXPECT_NEAR(reaction_step_limit(AlievPanfilov(proto::AlievPanfilovSpec())), 1.0 / 5.6, 1e-7);
}

// Why it exists: an excited FitzHugh-Nagumo cell stepped at dt = 16.7 (the diffusion limit at
// spacing 0.1 with D = 1e-4) runs away in whole half steps, and stays on its action potential
// when each half step is cut to the limit (7 sub-steps of 1.19).
TEST(IonicModel, CutReactionStepsKeepACoarseStepOnTheActionPotential) {
  const FitzHughNagumo model{proto::FitzHughNagumoSpec()};
  const double dt = 16.7, limit = reaction_step_limit(model);
  auto run = [&](int cuts) {
    double V = 0.3, w = 0.0, peak = 0.0;
    for (int step = 0; step < 60 && std::isfinite(V); ++step) {
      for (int k = 0; k < cuts; ++k) react_before_diffusion(model, V, w, 0.5 * dt / cuts);
      for (int k = 0; k < cuts; ++k) react_after_diffusion(model, V, w, 0.5 * dt / cuts);
      peak = std::max(peak, std::abs(V));
    }
    return std::pair{V, peak};
  };
  const auto whole = run(1);
  EXPECT_TRUE(!std::isfinite(whole.first) || whole.second > 2.0) << whole.second;
  const int cuts = static_cast<int>(std::ceil(0.5 * dt / limit));
  EXPECT_EQ(cuts, 7);
  const auto [V, peak] = run(cuts);
  std::cout << "dt 16.7: whole half steps peak |V| " << whole.second << ", cut " << peak
            << ", V after 1002 " << V << "\n";
  EXPECT_GT(peak, 0.9);         // it fires
  EXPECT_LT(peak, 1.05);        // and does not overshoot
  EXPECT_LT(std::abs(V), 0.3);  // and recovers
}

}  // namespace
}  // namespace cosph
