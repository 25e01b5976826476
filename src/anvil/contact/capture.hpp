// Mean planes and capture boxes of many faces at once, in structure-of-arrays form and
// vectorised across faces (simd::width faces per instruction). Lane by lane these are the
// IEEE operations of face_plane(), capture_box() and set_capture() in the same order (no
// contraction, the same comparisons for min and max), so every value has their bits.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace anvil {

struct FaceCaptures {
  std::vector<double> normal[3];    // unit normal of the mean plane
  std::vector<double> offset;       // normal . centre, m
  std::vector<double> warp;         // largest distance of a corner from the mean plane, m
  std::vector<double> lo[3], hi[3]; // capture box, m
  std::vector<double> centre[3];    // centre of the mean plane, m
  std::vector<double> len;          // |D1 x D2| of the diagonals D1, D2 (twice the area), m^2
  std::vector<double> diag;         // |D1| + |D2|, m
  // Sizes every array to n rounded up to a whole number of vectors.
  void resize(std::size_t n);
};

// Faces in structure-of-arrays form: corner a of face f is point corner[a][f] of the
// arrays x[0..2]; depth[f] is its depth. corner and depth must hold n values rounded up to
// a whole number of vectors (padding: any valid point index). Fills out (resized).
struct FaceCorners {
  const double* x[3];
  std::array<const int*, 4> corner;
  const double* depth;
  std::size_t n;
};
void compute_captures(const FaceCorners& faces, FaceCaptures& out);
// The same for the faces listed in `which` only (any order, each once); the other
// entries of out keep their values. With search_only, only what the search reads (normal,
// offset, warp, lo, hi) is written: centre, len and diag keep theirs too.
void compute_captures(const FaceCorners& faces, std::span<const int> which, FaceCaptures& out,
                      bool search_only = false);

} // namespace anvil
