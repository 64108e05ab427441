#include "core/particles.hpp"

#include <stdexcept>

namespace cosph {

template <int D>
int ParticleSet<D>::find(const std::string& name) const {
  for (std::size_t k = 0; k < infos_.size(); ++k)
    if (infos_[k].name == name) return static_cast<int>(k);
  return -1;
}

namespace {
template <typename T>
T zero_value() {
  if constexpr (std::is_same_v<T, double>)
    return 0.0;
  else
    return T::Zero();  // Eigen types are not zero-initialised by T{}
}
}  // namespace

template <int D>
void ParticleSet<D>::resize(std::size_t n) {
  size_ = n;
  for (auto& s : data_)
    std::visit(
        [n](auto& v) {
          using T = typename std::decay_t<decltype(v)>::value_type;
          v.resize(n, zero_value<T>());
        },
        s);
}

template <int D>
template <typename T>
std::vector<T>& ParticleSet<D>::add(const std::string& name, FieldKind kind, FieldFlags flags) {
  int k = find(name);
  if (k >= 0) {
    if (infos_[k].kind != kind)
      throw std::logic_error("field '" + name + "' of body '" + name_ +
                             "' registered twice with different kinds");
    auto& f = infos_[k].flags;
    f.output |= flags.output;
    f.checkpoint |= flags.checkpoint;
    f.exchange |= flags.exchange;
    return std::get<std::vector<T>>(data_[k]);
  }
  infos_.push_back({name, kind, flags});
  data_.emplace_back(std::vector<T>(size_, zero_value<T>()));
  return std::get<std::vector<T>>(data_.back());
}

template <int D>
template <typename T>
std::vector<T>& ParticleSet<D>::get(const std::string& name, FieldKind kind) {
  int k = find(name);
  if (k < 0) throw std::out_of_range("body '" + name_ + "' has no field '" + name + "'");
  if (infos_[k].kind != kind)
    throw std::logic_error("field '" + name + "' of body '" + name_ + "' has another kind");
  return std::get<std::vector<T>>(data_[k]);
}

template <int D>
template <typename T>
const std::vector<T>& ParticleSet<D>::get(const std::string& name, FieldKind kind) const {
  return const_cast<ParticleSet*>(this)->get<T>(name, kind);
}

template <int D>
std::vector<double>& ParticleSet<D>::add_scalar(const std::string& n, FieldFlags f) {
  return add<double>(n, FieldKind::Scalar, f);
}
template <int D>
std::vector<Vec<D>>& ParticleSet<D>::add_vector(const std::string& n, FieldFlags f) {
  return add<Vec<D>>(n, FieldKind::Vector, f);
}
template <int D>
std::vector<Mat<D>>& ParticleSet<D>::add_matrix(const std::string& n, FieldFlags f) {
  return add<Mat<D>>(n, FieldKind::Matrix, f);
}
template <int D>
std::vector<double>& ParticleSet<D>::scalar(const std::string& n) {
  return get<double>(n, FieldKind::Scalar);
}
template <int D>
const std::vector<double>& ParticleSet<D>::scalar(const std::string& n) const {
  return get<double>(n, FieldKind::Scalar);
}
template <int D>
std::vector<Vec<D>>& ParticleSet<D>::vector(const std::string& n) {
  return get<Vec<D>>(n, FieldKind::Vector);
}
template <int D>
const std::vector<Vec<D>>& ParticleSet<D>::vector(const std::string& n) const {
  return get<Vec<D>>(n, FieldKind::Vector);
}
template <int D>
std::vector<Mat<D>>& ParticleSet<D>::matrix(const std::string& n) {
  return get<Mat<D>>(n, FieldKind::Matrix);
}
template <int D>
const std::vector<Mat<D>>& ParticleSet<D>::matrix(const std::string& n) const {
  return get<Mat<D>>(n, FieldKind::Matrix);
}

template <int D>
const FieldInfo& ParticleSet<D>::info(const std::string& name) const {
  int k = find(name);
  if (k < 0) throw std::out_of_range("body '" + name_ + "' has no field '" + name + "'");
  return infos_[k];
}

template <int D>
std::vector<std::string> ParticleSet<D>::field_names() const {
  std::vector<std::string> names;
  for (const auto& i : infos_) names.push_back(i.name);
  return names;
}

template <int D>
std::span<double> ParticleSet<D>::raw(const std::string& name) {
  int k = find(name);
  if (k < 0) throw std::out_of_range("body '" + name_ + "' has no field '" + name + "'");
  return std::visit(
      [](auto& v) -> std::span<double> {
        using T = typename std::decay_t<decltype(v)>::value_type;
        if constexpr (std::is_same_v<T, double>)
          return {v.data(), v.size()};
        else
          return {v.empty() ? nullptr : v.data()->data(), v.size() * T::SizeAtCompileTime};
      },
      data_[k]);
}

template <int D>
std::span<const double> ParticleSet<D>::raw(const std::string& name) const {
  auto s = const_cast<ParticleSet*>(this)->raw(name);
  return {s.data(), s.size()};
}

template <int D>
void ParticleSet<D>::permute(const std::vector<Index>& order) {
  if (order.size() != size_) throw std::logic_error("permutation of wrong size");
  for (auto& s : data_)
    std::visit(
        [&](auto& v) {
          auto copy = v;
          for (std::size_t i = 0; i < order.size(); ++i) v[i] = copy[order[i]];
        },
        s);
}

template <int D>
void ParticleSet<D>::select(const std::vector<Index>& from) {
  for (Index i : from)
    if (i >= size_) throw std::logic_error("selection of a particle beyond the set");
  for (auto& s : data_)
    std::visit(
        [&](auto& v) {
          auto copy = v;
          v.resize(from.size());
          for (std::size_t i = 0; i < from.size(); ++i) v[i] = copy[from[i]];
        },
        s);
  size_ = from.size();
}

template class ParticleSet<2>;
template class ParticleSet<3>;

}  // namespace cosph
