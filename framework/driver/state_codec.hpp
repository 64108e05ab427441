// A module's StateRecord as the checkpoint message and back, children included (a coupler's
// record nests its children's). One codec for checkpoint files and, later, the wire.
#pragma once

#include "checkpoint.pb.h"
#include "driver/module.hpp"

namespace cosph {

void encode_state(const StateRecord& state, proto::ModuleState& out);
StateRecord decode_state(const proto::ModuleState& in);

}  // namespace cosph
