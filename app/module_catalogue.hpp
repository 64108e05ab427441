// The module types this build offers, registered explicitly (static libraries would drop
// self-registering static objects).
#pragma once

#include "driver/registry.hpp"

namespace cosph {

const ModuleRegistry& builtin_modules();

}  // namespace cosph
