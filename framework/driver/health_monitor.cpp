#include "driver/health_monitor.hpp"

#include <cmath>
#include <sstream>

namespace cosph {

namespace {

template <class V>
std::string text_of(const V& x) {
  std::ostringstream s;
  s << x.transpose();
  return s.str();
}

template <int D>
void check_body(const BodyView<D>& view, bool check_domain, unsigned long long step, double time) {
  const ParticleSet<D>& p = *view.particles;
  const auto* x = p.has("position") ? &p.vector("position") : nullptr;
  auto fail = [&](const std::string& quantity, std::size_t i, double value,
                  const std::string& expected) {
    const std::string position = x && i < x->size() ? text_of((*x)[i]) : std::string();
    throw HealthError(
        health_failure_message({step, time, view.module, p.name(), position},
                               {quantity, static_cast<long long>(i), value, expected}));
  };
  for (std::size_t k = 0; k < p.field_count(); ++k) {
    const FieldInfo& info = p.info(k);
    const auto raw = p.raw(info.name);
    const std::size_t components = ParticleSet<D>::components(info.kind);
    for (std::size_t c = 0; c < raw.size(); ++c)
      if (!std::isfinite(raw[c])) fail(info.name, c / components, raw[c], "a finite value");
  }
  if (check_domain && x) {
    const Domain<D>& d = view.domain;
    for (std::size_t i = 0; i < x->size(); ++i)
      for (int a = 0; a < D; ++a)
        if ((*x)[i][a] < d.lower[a] || (*x)[i][a] > d.upper[a])
          fail(std::string("position.") + "xyz"[a], i, (*x)[i][a], "inside the domain");
  }
}

}  // namespace

std::string health_failure_message(const HealthContext& where, const HealthProblem& problem) {
  std::ostringstream msg;
  msg << "health check failed at ";
  if (where.step)
    msg << "step " << *where.step << " (t = " << where.time << ")";
  else
    msg << "t = " << where.time;
  msg << ": module '" << where.module << "'";
  if (!where.body.empty()) msg << ", body '" << where.body << "'";
  msg << ": " << problem.quantity << " = " << problem.value;
  if (problem.particle >= 0) msg << " at particle " << problem.particle;
  if (!where.position.empty()) msg << ", position (" << where.position << ")";
  msg << "; expected " << problem.expected;
  return msg.str();
}

void HealthMonitor::check(const std::vector<const Module*>& modules, unsigned long long step,
                          double time) const {
  for (const Module* m : modules) {
    BodyViews views;
    m->bodies(views);
    for (const auto& b : views.bodies2) check_body<2>(b, check_domain_, step, time);
    for (const auto& b : views.bodies3) check_body<3>(b, check_domain_, step, time);
    if (auto problem = m->check_health()) {
      std::string position;
      if (problem->particle >= 0) {
        const auto find = [&](const auto& list) {
          for (const auto& b : list)
            if (b.particles->has("position") &&
                static_cast<std::size_t>(problem->particle) < b.particles->size()) {
              position = text_of(b.particles->vector("position")[problem->particle]);
              return true;
            }
          return false;
        };
        if (!find(views.bodies2)) find(views.bodies3);
      }
      throw HealthError(
          health_failure_message({step, time, m->info().name, "", position}, *problem));
    }
  }
}

}  // namespace cosph
