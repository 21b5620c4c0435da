#pragma once
// Diffusion coefficients at faces and at the walls, shared by the explicit viscous fluxes
// (viscous_flux.cpp) and the implicit diffusion (implicit_diffusion.cpp), for a double or a
// vector of cells (simd_pair.hpp).

namespace shaker::continuum {

/// A face's coefficient from its two cells' values: the harmonic mean (viscous_flux.cpp says
/// why), zero where both are zero.
template <class S> S harmonic_mean(S a, S b) {
  const S sum = a + b;
  return sum > 0.0 ? 2.0 * a * b / sum : S{};
}

/// A coefficient at the wall from the wall cell's value x0 and the next cell's x1 (centres at
/// h / 2 and 3 h / 2): the linear extrapolation, or x0 where that leaves [x0 / 2, 3 x0 / 2]
/// (the layer's edge beside the wall; the cap also bounds the wall row's stiffness, which
/// Operator::diffusive_step allows for).
template <class S> S extrapolated_to_wall(S x0, S x1) {
  const S wall = 1.5 * x0 - 0.5 * x1;
  return (wall >= 0.5 * x0) & (wall <= 1.5 * x0) ? wall : x0;
}

}  // namespace shaker::continuum
