#pragma once
// The channels of a third-order jet of a scalar function of d = 1 or 2 inputs: the value and
// every distinct partial derivative up to order 3, in a fixed order shared by cpu/ and cuda/.
//
//   d = 1:  0:f  1:f_x  2:f_xx  3:f_xxx
//   d = 2:  0:f  1:f_x  2:f_y  3:f_xx  4:f_xy  5:f_yy  6:f_xxx  7:f_xxy  8:f_xyy  9:f_yyy
//
// A jet truncated at order k keeps the first jet_channels(d, k) channels.
#ifdef __CUDACC__
#define YH_HD __host__ __device__
#else
#define YH_HD
#endif

namespace yarnhom {

inline constexpr int kMaxJetChannels = 10;

YH_HD constexpr int jet_channels(int d, int order) {
  // 1 + d + d(d+1)/2 + d(d+1)(d+2)/6, truncated.
  int c = 1;
  if (order >= 1) c += d;
  if (order >= 2) c += d * (d + 1) / 2;
  if (order >= 3) c += d * (d + 1) * (d + 2) / 6;
  return c;
}

// First channel of each order.
YH_HD constexpr int jet_first(int d, int order) { return order == 0 ? 0 : jet_channels(d, order - 1); }

// Second-order channel for the unordered pair (i, j).
YH_HD constexpr int jet_ch2(int d, int i, int j) {
  if (d == 1) return 2;
  int s = i + j;  // (0,0)->3 (0,1)->4 (1,1)->5
  return 3 + s;
}

// Third-order channel for the unordered triple (i, j, k).
YH_HD constexpr int jet_ch3(int d, int i, int j, int k) {
  if (d == 1) return 3;
  int s = i + j + k;  // number of y's: xxx->6 xxy->7 xyy->8 yyy->9
  return 6 + s;
}

// Index tuples of the second- and third-order channels, in channel order.
struct JetPair {
  int i, j;
};
struct JetTriple {
  int i, j, k;
};
YH_HD constexpr JetPair jet_pair(int d, int n) {  // n-th second-order channel
  if (d == 1) return {0, 0};
  return n == 0 ? JetPair{0, 0} : n == 1 ? JetPair{0, 1} : JetPair{1, 1};
}
YH_HD constexpr JetTriple jet_triple(int d, int n) {  // n-th third-order channel
  if (d == 1) return {0, 0, 0};
  return n == 0 ? JetTriple{0, 0, 0} : n == 1 ? JetTriple{0, 0, 1} : n == 2 ? JetTriple{0, 1, 1} : JetTriple{1, 1, 1};
}
YH_HD constexpr int jet_num_pairs(int d) { return d * (d + 1) / 2; }
YH_HD constexpr int jet_num_triples(int d) { return d * (d + 1) * (d + 2) / 6; }

}  // namespace yarnhom
