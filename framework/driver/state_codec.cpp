#include "driver/state_codec.hpp"

namespace cosph {

void encode_state(const StateRecord& state, proto::ModuleState& out) {
  out.set_name(state.name);
  out.set_type(state.type);
  for (const auto& [name, values] : state.arrays) {
    auto* f = out.add_arrays();
    f->set_name(name);
    f->mutable_values()->Add(values.begin(), values.end());
  }
  for (const auto& [name, v] : state.scalars) (*out.mutable_scalars())[name] = v;
  for (const auto& [name, v] : state.integers) (*out.mutable_integers())[name] = v;
  for (const auto& child : state.children) encode_state(child, *out.add_children());
}

StateRecord decode_state(const proto::ModuleState& in) {
  StateRecord state;
  state.name = in.name();
  state.type = in.type();
  for (const auto& f : in.arrays())
    state.arrays[f.name()].assign(f.values().begin(), f.values().end());
  for (const auto& [name, v] : in.scalars()) state.scalars[name] = v;
  for (const auto& [name, v] : in.integers()) state.integers[name] = v;
  for (const auto& child : in.children()) state.children.push_back(decode_state(child));
  return state;
}

}  // namespace cosph
