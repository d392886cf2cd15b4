#pragma once
// Interpolation for up to kLookupBatch samples of one triangle at once (private to the pipeline):
// the untextured colour and, for textured samples, the texture lookup's inputs (uv and its analytic
// derivatives), in double vectors, four samples per vector. Element by element it is the
// arithmetic of untextured_colour and texture_lookup (sample_shading.hpp), in the same order, with
// no fused multiply-add, so each sample gets the same bits as from those scalar functions.
#include <cstdint>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/texture/sample_batch.hpp"

namespace mipraster {
namespace kernels {

/// Screen weights of the samples, one array per vertex.
struct BatchWeights {
    double l0[kLookupBatch], l1[kLookupBatch], l2[kLookupBatch];
    int count = 0;
};

/// True when interpolate_batch gives a triangle's samples what the scalar functions give them:
/// constant, flat, screen or perspective shading; uv interpolated in screen space or
/// perspective-correct with analytic derivatives (or none); the triangle not clipped.
bool interpolates_in_batches(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t);

/// The shading the batches of a triangle with vertex colours `colors` take, for `shading`: flat
/// where screen or perspective shading has one colour on all three vertices (the clamp to the
/// vertices' range makes every weighted sum that colour: the same bits, without the sums).
/// Once per triangle, not per batch.
Shading batch_shading(Shading shading, const VertexValues& colors);

/// For samples i < w.count of triangle t: colour[i] = untextured_colour at weights w, and lane i of
/// `lookups` = texture_lookup's uv and derivatives as floats (lookups.count = w.count). `shading`:
/// the draw's, or batch_shading of it (faster, the same bits).
void interpolate_batch(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t,
                       const VertexValues& colors, const TriangleUvs& uvs, const BatchWeights& w, glm::vec4* colour,
                       LookupBatch& lookups);

/// For samples i < w.count of an untextured triangle t, not clipped: colour[i] = untextured_colour
/// at weights w, the same bits (`shading` as for interpolate_batch).
void interpolate_colours(const DrawInputs& draw, Shading shading, const SetupTriangle& t, const VertexValues& colors,
                         const BatchWeights& w, glm::vec4* colour);

}  // namespace kernels
}  // namespace mipraster
