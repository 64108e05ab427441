// Small fixed-size linear-algebra types shared by every component. 2D and 3D code is written once
// against the dimension parameter D and explicitly instantiated for D = 2 and D = 3.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace cosph {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;
template <int D>
using Mat = Eigen::Matrix<double, D, D>;

using Index = std::uint32_t;  // particle index; 4 G particles is far beyond a 2-core machine

}  // namespace cosph
