#include "module_catalogue.hpp"

#include "active_stress/active_stress_module.hpp"
#include "diffusion/diffusion_module.hpp"
#include "fluid_wcsph/fluid_module.hpp"
#include "fsi/fsi_coupler.hpp"
#include "monodomain/monodomain_module.hpp"
#include "solid_tlsph/solid_module.hpp"

namespace cosph {

const ModuleRegistry& builtin_modules() {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    r.add("diffusion", make_diffusion_module);
    r.add("monodomain", make_monodomain_module);
    r.add("active_stress", make_active_stress_module);
    r.add("solid", make_solid_module);
    r.add("fluid", make_fluid_module);
    r.couplers().add("fsi", {"fluid", "solid"}, make_fsi_coupler);
    return r;
  }();
  return registry;
}

}  // namespace cosph
