#ifndef CLOTHWIND_RENDER_NOISE_H_
#define CLOTHWIND_RENDER_NOISE_H_

#include <cstdint>

namespace clothwind::render {

// Smooth 2-D value noise in [0, 1] on an integer lattice (hash of the lattice point and seed,
// smoothstep interpolation). Used for knit heather, grass, tree lines and cloud-free skies'
// slight variation: cheap, seedable, no tables.
// Inputs: x, y  coordinates in lattice units; seed  selects an independent noise field.
float ValueNoise(float x, float y, uint64_t seed);

// Fractal sum of `octaves` ValueNoise layers (lacunarity 2, gain 0.5), normalised to [0, 1].
float FractalNoise(float x, float y, uint64_t seed, int octaves);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_NOISE_H_
