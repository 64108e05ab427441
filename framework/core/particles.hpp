// Structure-of-arrays particle storage. A ParticleSet holds one body's particles as named fields
// (scalar, vector or matrix per particle), registered by the module that owns the body. Field
// metadata says which fields are written to output files, saved in checkpoints and exchanged
// through ports. There are no per-particle objects: each field is one contiguous array.
#pragma once

#include <deque>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/types.hpp"

namespace cosph {

enum class FieldKind { Scalar, Vector, Matrix };

struct FieldFlags {
  bool output = false;      // written to VTP files
  bool checkpoint = false;  // part of the state saved for restart
  bool exchange = false;    // may be read or written through a port
};

struct FieldInfo {
  std::string name;
  FieldKind kind = FieldKind::Scalar;
  FieldFlags flags;
};

template <int D>
class ParticleSet {
 public:
  using Storage = std::variant<std::vector<double>, std::vector<Vec<D>>, std::vector<Mat<D>>>;

  explicit ParticleSet(std::string name = "particles") : name_(std::move(name)) {}

  const std::string& name() const { return name_; }
  std::size_t size() const { return size_; }

  // Changes the number of particles; new entries of every field are zero.
  void resize(std::size_t n);

  // Registers a field (zero-filled). Registering an existing name with the same kind returns the
  // existing field and merges the flags; a different kind is a programming error (throws).
  std::vector<double>& add_scalar(const std::string& name, FieldFlags flags = {});
  std::vector<Vec<D>>& add_vector(const std::string& name, FieldFlags flags = {});
  std::vector<Mat<D>>& add_matrix(const std::string& name, FieldFlags flags = {});

  bool has(const std::string& name) const { return find(name) >= 0; }
  std::vector<double>& scalar(const std::string& name);
  const std::vector<double>& scalar(const std::string& name) const;
  std::vector<Vec<D>>& vector(const std::string& name);
  const std::vector<Vec<D>>& vector(const std::string& name) const;
  std::vector<Mat<D>>& matrix(const std::string& name);
  const std::vector<Mat<D>>& matrix(const std::string& name) const;

  std::size_t field_count() const { return infos_.size(); }
  const FieldInfo& info(std::size_t k) const { return infos_[k]; }
  const FieldInfo& info(const std::string& name) const;
  std::vector<std::string> field_names() const;

  // Raw contiguous view of a field as doubles (components of one particle are consecutive), and
  // the number of doubles per particle (1, D or D*D). Used by output, checkpoints and ports.
  std::span<double> raw(const std::string& name);
  std::span<const double> raw(const std::string& name) const;
  static std::size_t components(FieldKind kind) {
    return kind == FieldKind::Scalar ? 1 : kind == FieldKind::Vector ? D : D * D;
  }

  // Reorders every field: new[i] = old[order[i]]. Used by the cell sort for memory locality.
  void permute(const std::vector<Index>& order);
  // The set becomes the particles at these indices, in this order (repeats copy a particle,
  // omissions remove it): the size changes to from.size(). Open boundaries add and remove
  // particles through it.
  void select(const std::vector<Index>& from);

 private:
  int find(const std::string& name) const;
  template <typename T>
  std::vector<T>& add(const std::string& name, FieldKind kind, FieldFlags flags);
  template <typename T>
  std::vector<T>& get(const std::string& name, FieldKind kind);
  template <typename T>
  const std::vector<T>& get(const std::string& name, FieldKind kind) const;

  std::string name_;
  std::size_t size_ = 0;
  std::vector<FieldInfo> infos_;
  std::deque<Storage> data_;  // deque: registering a field never moves the others
};

extern template class ParticleSet<2>;
extern template class ParticleSet<3>;

}  // namespace cosph
