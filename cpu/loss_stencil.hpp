#pragma once
// The paper's finite-difference stencil for the third derivatives of L_C, written out as
// (offset, coefficient) lists in units of the step eps; divide the sum by 2 eps^3.
//   1D:  f''' ~ [f(x+2e) - 2 f(x+e) + 2 f(x-e) - f(x-2e)] / (2 e^3)          (the paper's)
//   2D:  f_xxx, f_yyy by the same stencil along each axis; the mixed ones as the central
//        difference of second differences, e.g.
//        f_xxy ~ [(f(x+e,y+e) - 2 f(x,y+e) + f(x-e,y+e)) - (same at y-e)] / (2 e^3)
// (our extension to 2D; the paper states the 1D stencil only).
namespace yarnhom::cpu {

struct StencilTap {
  int dx, dy;
  double coef;
};

inline constexpr StencilTap kStencil1D[4] = {{2, 0, 1}, {1, 0, -2}, {-1, 0, 2}, {-2, 0, -1}};
// [triple][tap], triples in jet order xxx, xxy, xyy, yyy; 1D-type rows have 4 taps, mixed 6.
inline constexpr int kStencil2DTaps[4] = {4, 6, 6, 4};
inline constexpr StencilTap kStencil2D[4][6] = {
    {{2, 0, 1}, {1, 0, -2}, {-1, 0, 2}, {-2, 0, -1}, {0, 0, 0}, {0, 0, 0}},
    {{1, 1, 1}, {0, 1, -2}, {-1, 1, 1}, {1, -1, -1}, {0, -1, 2}, {-1, -1, -1}},
    {{1, 1, 1}, {1, 0, -2}, {1, -1, 1}, {-1, 1, -1}, {-1, 0, 2}, {-1, -1, -1}},
    {{0, 2, 1}, {0, 1, -2}, {0, -1, 2}, {0, -2, -1}, {0, 0, 0}, {0, 0, 0}},
};

}  // namespace yarnhom::cpu
