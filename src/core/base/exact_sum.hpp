// Sums of doubles without rounding, whatever the order of the terms: each term is split
// into its 53-bit integer mantissa and exponent and added into a fixed-point accumulator
// whose limbs hold 32 bits each in 64-bit integers (2^31 additions before a limb could
// overflow; the accumulator is normalised before that). Accumulators of several ranks
// add limb by limb as integers (exact in any order) once normalised; the exact total has
// one normalised form, rounded once to a double: the result depends on the terms only.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace mfree {

class ExactSum {
 public:
  // limb k weighs 2^(32 k - 1152): the lowest bit of the smallest subnormal (2^-1074)
  // lies 26 or more bits above the bottom, and 2^1024 (beyond the largest double) below
  // limb 68, leaving limb 69 for the carries of up to 2^63 terms.
  static constexpr int kLimbs = 70;
  static constexpr int kBias = 1152;
  // the counts of +inf, -inf and NaN terms travel with the limbs
  static constexpr int kWords = kLimbs + 3;

  void add(double x) {
    // x's sign, exponent and mantissa from its bits (frexp and ldexp are library calls)
    uint64_t b = 0;
    std::memcpy(&b, &x, sizeof b);
    const int ex = static_cast<int>((b >> 52) & 0x7ff);
    uint64_t man = b & ((uint64_t{1} << 52) - 1);
    if (ex == 0x7ff) {
      ++w_[kLimbs + (man ? 2 : (b >> 63 ? 1 : 0))];
      return;
    }
    if (ex == 0 && man == 0) return;
    if (ex != 0) man |= uint64_t{1} << 52;  // (subnormals: exponent 1, no hidden bit)
    const int64_t mi = b >> 63 ? -static_cast<int64_t>(man) : static_cast<int64_t>(man);
    const int pos = (ex == 0 ? 1 : ex) - 1075 + kBias;  // x = mi 2^(pos - kBias), pos >= 78
    const int k = pos / 32;
    // (a product, not a left shift: shifting a negative value is undefined before C++20)
    __int128 v = static_cast<__int128>(mi) * (static_cast<__int128>(1) << (pos % 32));
    // v = c0 + c1 2^32 + c2 2^64, c0 and c1 in [0, 2^32), c2 signed and small
    w_[k] += static_cast<int64_t>(static_cast<uint64_t>(v) & 0xffffffffu);
    v >>= 32;
    w_[k + 1] += static_cast<int64_t>(static_cast<uint64_t>(v) & 0xffffffffu);
    v >>= 32;
    w_[k + 2] += static_cast<int64_t>(v);
    if (++adds_ == (int64_t{1} << 30)) normalise();
  }

  // Another normalised accumulator's words (each rank's, in any order).
  void add_words(const int64_t *w) {
    for (int k = 0; k < kWords; ++k) w_[k] += w[k];
    if (++adds_ >= (int64_t{1} << 30)) normalise();
  }

  // Limbs 0 .. kLimbs-2 in [0, 2^32), the sign and any excess in the top limb (whose
  // magnitude stays far below 2^53: the normalised words are exact as doubles).
  void normalise() {
    for (int k = 0; k + 1 < kLimbs; ++k) {
      const int64_t carry = w_[k] >> 32;  // (arithmetic: floor)
      w_[k] -= carry * (int64_t{1} << 32);
      w_[k + 1] += carry;
    }
    adds_ = 0;
  }

  int64_t *words() { return w_; }

  // The exact total rounded to the nearest double (once, from its canonical form).
  double value() {
    normalise();
    const int64_t pinf = w_[kLimbs], ninf = w_[kLimbs + 1], nan = w_[kLimbs + 2];
    if (nan > 0 || (pinf > 0 && ninf > 0)) return std::nan("");
    if (pinf > 0) return HUGE_VAL;
    if (ninf > 0) return -HUGE_VAL;
    const bool negative = w_[kLimbs - 1] < 0;
    if (negative) {
      for (int k = 0; k < kLimbs; ++k) w_[k] = -w_[k];
      normalise();
    }
    int hi = kLimbs - 1;
    while (hi >= 0 && w_[hi] == 0) --hi;
    if (hi < 0) return 0.0;
    // the top three limbs and a sticky bit for the rest: at least 65 significant bits,
    // so the sticky bit lies far below the rounding position of the conversion
    unsigned __int128 t = 0;
    bool sticky = false;
    for (int k = hi; k >= hi - 2; --k) t = (t << 32) | (k >= 0 ? static_cast<uint64_t>(w_[k]) : 0u);
    for (int k = hi - 3; k >= 0 && !sticky; --k) sticky = w_[k] != 0;
    if (sticky) t |= 1;
    const double d = std::ldexp(static_cast<double>(t), 32 * (hi - 2) - kBias);
    return negative ? -d : d;
  }

 private:
  int64_t w_[kWords] = {0};
  int64_t adds_ = 0;
};

}  // namespace mfree
