#include "driver/health_monitor.hpp"

#include <cmath>
#include <sstream>

namespace cosph {

namespace {

std::string where(unsigned long long step, double time) {
  std::ostringstream s;
  s << "health check failed at step " << step << " (t = " << time << "): ";
  return s.str();
}

template <int D>
void check_body(const BodyView<D>& view, bool check_domain, unsigned long long step, double time) {
  const ParticleSet<D>& p = *view.particles;
  const auto* x = p.has("position") ? &p.vector("position") : nullptr;
  auto fail = [&](const std::string& quantity, std::size_t i, double value,
                  const std::string& expected) {
    std::ostringstream msg;
    msg << where(step, time) << "module '" << view.module << "', body '" << p.name()
        << "': " << quantity << " = " << value << " at particle " << i;
    if (x && i < x->size()) msg << ", position (" << (*x)[i].transpose() << ")";
    msg << "; expected " << expected;
    throw HealthError(msg.str());
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

void HealthMonitor::check(const std::vector<const Module*>& modules, unsigned long long step,
                          double time) const {
  for (const Module* m : modules) {
    BodyViews views;
    m->bodies(views);
    for (const auto& b : views.bodies2) check_body<2>(b, check_domain_, step, time);
    for (const auto& b : views.bodies3) check_body<3>(b, check_domain_, step, time);
    if (auto problem = m->check_health()) {
      std::ostringstream msg;
      msg << where(step, time) << "module '" << m->info().name << "': " << problem->quantity
          << " = " << problem->value;
      if (problem->particle >= 0) {
        msg << " at particle " << problem->particle;
        BodyViews v;
        m->bodies(v);
        const auto position = [&](const auto& list) {
          for (const auto& b : list)
            if (b.particles->has("position") &&
                static_cast<std::size_t>(problem->particle) < b.particles->size()) {
              msg << ", position ("
                  << b.particles->vector("position")[problem->particle].transpose() << ")";
              return true;
            }
          return false;
        };
        if (!position(v.bodies2)) position(v.bodies3);
      }
      msg << "; expected " << problem->expected;
      throw HealthError(msg.str());
    }
  }
}

}  // namespace cosph
