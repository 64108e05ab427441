// The fluid-structure interaction coupler (`couplers[i].fsi`).
#pragma once

#include <memory>
#include <vector>

#include "driver/coupler_registry.hpp"

namespace cosph {

// Children in role order: fluid, solid.
std::unique_ptr<Coupler> make_fsi_coupler(const proto::CouplerSpec& spec,
                                          std::vector<std::unique_ptr<Module>> children,
                                          const CouplerContext& context);

}  // namespace cosph
