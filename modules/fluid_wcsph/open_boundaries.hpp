// Open boundaries of a fluid (scene keys `inflow` and `outflow`): an inflow buffer whose
// particles move with a prescribed velocity profile and recycle themselves, and an outflow plane
// past which particles leave. Particles are created and removed only here, once per advection
// step, keeping the particle arrays compact and in an order that does not depend on the thread
// count.
#pragma once

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/particles.hpp"
#include "expression/expression.hpp"
#include "scene.pb.h"

namespace cosph {

template <int D>
class OpenBoundaries {
 public:
  // Validates the scene's open boundaries (key: the fluid's key path; sound_speed: the fluid's,
  // which a prescribed inflow speed must stay below).
  OpenBoundaries(const proto::FluidSpec& spec, double support, double sound_speed,
                 const std::string& key)
      : support_(support), sound_speed_(sound_speed) {
    if (spec.has_inflow()) {
      const auto& in = spec.inflow();
      const std::string& path = path_ = key + ".inflow";
      if (in.axis() >= D) throw ConfigError(path + ".axis", "axis must be below the dimension");
      inflow_ = true;
      inflow_axis_ = in.axis();
      for (int a = 0; a < in.velocity_size(); ++a) {
        try {
          velocity_.push_back(Expression::parse(in.velocity(a), {"x", "y", "z", "t"}));
        } catch (const ExpressionError& e) {
          throw ConfigError(path + ".velocity[" + std::to_string(a) + "]", e.what());
        }
      }
      for (int a = 0; a < D; ++a) {
        lower_[a] = in.buffer().lower(a);
        upper_[a] = in.buffer().upper(a);
        if (!(lower_[a] < upper_[a]))
          throw ConfigError(
              path + ".buffer",
              "the box needs lower < upper along every axis (axis " + std::to_string(a) + ")");
      }
      if (!(length() >= support))
        throw ConfigError(path + ".buffer", "the buffer must be at least one kernel support (" +
                                                std::to_string(support) + ") long along the axis");
    }
    if (spec.has_outflow()) {
      if (spec.outflow().axis() >= D)
        throw ConfigError(key + ".outflow.axis", "axis must be below the dimension");
      outflow_ = true;
      outflow_axis_ = spec.outflow().axis();
      outflow_position_ = spec.outflow().position();
    }
  }

  bool any() const { return inflow_ || outflow_; }
  bool has_inflow() const { return inflow_; }
  std::vector<std::string> features() const {
    std::vector<std::string> f;
    if (inflow_) f.push_back("inflow buffer");
    if (outflow_) f.push_back("outflow");
    return f;
  }

  // Registers the buffer marker (checkpointed with the particles) and marks the particles that
  // start inside the buffer.
  void initialize(ParticleSet<D>& fluid, double t) const {
    if (!inflow_) return;
    auto& buffer = fluid.add_scalar("in_buffer", {.checkpoint = true});
    const auto& x = fluid.vector("position");
    for (std::size_t i = 0; i < x.size(); ++i) buffer[i] = inside_buffer(x[i]) ? 1.0 : 0.0;
    impose(fluid, t);
  }

  // Buffer particles, and particles within one kernel support of the outflow plane, have
  // truncated neighbourhoods: their summed density would be too low (a spurious suction), so
  // they keep the larger of the summed and the continuity density, and the transport-velocity
  // shift, which would push them out of the fluid, leaves them alone. Bind it to the particle
  // arrays once per loop; it reads no field names per particle.
  struct Truncation {
    const std::vector<double>* buffer = nullptr;
    const std::vector<Vec<D>>* x = nullptr;
    int axis = 0;
    double from = INFINITY;  // outflow position minus one support
    bool operator()(std::size_t i) const {
      return (buffer && (*buffer)[i] > 0.0) || (*x)[i][axis] > from;
    }
  };
  Truncation truncation(const ParticleSet<D>& fluid) const {
    Truncation t;
    t.buffer = inflow_ ? &fluid.scalar("in_buffer") : nullptr;
    t.x = &fluid.vector("position");
    t.axis = outflow_axis_;
    if (outflow_) t.from = outflow_position_ - support_;
    return t;
  }

  // The buffer particles take the prescribed velocity at time t. A prescribed speed at or past
  // the sound speed (or not finite) is refused with the key that prescribes it: the scheme could
  // not follow it (the acoustic step would shrink without bound).
  void impose(ParticleSet<D>& fluid, double t) const {
    if (!inflow_) return;
    const auto& x = fluid.vector("position");
    auto& v = fluid.vector("velocity");
    const auto& buffer = fluid.scalar("in_buffer");
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (buffer[i] == 0.0) continue;
      std::array<double, 4> p{0.0, 0.0, 0.0, t};
      for (int a = 0; a < D; ++a) p[a] = x[i][a];
      for (int a = 0; a < D; ++a) v[i][a] = velocity_[a].evaluate(p);
      if (!(v[i].norm() <= sound_speed_)) throw_supersonic(v[i].norm(), p);
    }
  }

  // Once per advection step: particles past the outflow plane leave; a buffer particle that has
  // left its box downstream becomes free and a copy of it re-enters one buffer length upstream
  // (with the prescribed velocity at time t). The survivors keep their order and the copies go
  // to the end. Returns whether the particle set changed.
  bool update(ParticleSet<D>& fluid, double t) const {
    const std::size_t n = fluid.size();
    const auto& x = fluid.vector("position");
    const std::vector<double>* buffer = inflow_ ? &fluid.scalar("in_buffer") : nullptr;
    std::vector<Index> keep, spawn;
    keep.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (outflow_ && x[i][outflow_axis_] > outflow_position_) continue;
      keep.push_back(Index(i));
      if (buffer && (*buffer)[i] > 0.0 && x[i][inflow_axis_] > upper_[inflow_axis_])
        spawn.push_back(Index(i));
    }
    if (keep.size() == n && spawn.empty()) return false;
    const std::size_t survivors = keep.size();
    keep.insert(keep.end(), spawn.begin(), spawn.end());
    fluid.select(keep);
    if (spawn.empty()) return true;
    auto& position = fluid.vector("position");
    auto& marker = fluid.scalar("in_buffer");
    for (std::size_t i = 0; i < survivors; ++i)
      if (marker[i] > 0.0 && position[i][inflow_axis_] > upper_[inflow_axis_]) marker[i] = 0.0;
    for (std::size_t i = survivors; i < position.size(); ++i) {
      position[i][inflow_axis_] -= length();
      marker[i] = 1.0;
    }
    impose(fluid, t);
    return true;
  }

 private:
  double length() const { return upper_[inflow_axis_] - lower_[inflow_axis_]; }

  [[noreturn]] void throw_supersonic(double speed, const std::array<double, 4>& p) const {
    std::ostringstream m;
    m << "the prescribed speed is " << speed << " at t = " << p[3] << ", position (" << p[0];
    for (int a = 1; a < D; ++a) m << ", " << p[a];
    m << "): it must stay below the sound speed " << sound_speed_
      << " (raise max_velocity or sound_speed if the flow is meant to be this fast)";
    throw ConfigError(path_ + ".velocity", m.str());
  }
  bool inside_buffer(const Vec<D>& x) const {
    for (int a = 0; a < D; ++a)
      if (x[a] < lower_[a] || x[a] > upper_[a]) return false;
    return true;
  }

  double support_, sound_speed_;
  std::string path_;  // the inflow's key path, for errors while running
  bool inflow_ = false, outflow_ = false;
  int inflow_axis_ = 0, outflow_axis_ = 0;
  double outflow_position_ = 0.0;
  Vec<D> lower_ = Vec<D>::Zero(), upper_ = Vec<D>::Zero();
  std::vector<Expression> velocity_;
};

}  // namespace cosph
