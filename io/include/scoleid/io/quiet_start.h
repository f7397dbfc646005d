#pragma once
// A record's quiet start: the noise a channel reads before the first input acts (docs/data.md §2,
// "Noise from the quiet start"). A record that starts at rest holds its channels' noise (and any
// offset) until the first input exceeds a twentieth of its peak. With at least kQuietSamples
// samples there, less a margin of kQuietMargin (a DAQ filter's pre-ringing), a channel's level is
//
//   σ̂² = min( variance about the mean ,  mean square first difference / 2 ),
//
// both σ² for white noise; the second is the smaller for a drift or a start that already rings, so
// a start that is not quiet can only lower σ̂, never raise it. A quiet start that reads exactly
// zero (a clean simulation) says nothing of the noise: σ̂ = 0, not usable.
#include <cstddef>

namespace scoleid::io {

constexpr int kQuietSamples = 50, kQuietMargin = 4;

// The first of n samples at which |x| exceeds a twentieth of its peak |x|; n when x is all zero.
std::size_t trigger_sample(const double* x, std::size_t n);
// The quiet samples before a trigger at sample `trigger` (trigger − kQuietMargin), or 0 when fewer
// than kQuietSamples + kQuietMargin samples precede it.
std::size_t quiet_samples(std::size_t trigger);
// σ̂ of the first `quiet` samples of y (above); 0 when not usable (zero, not finite, fewer than 2).
double quiet_start_noise(const double* y, std::size_t quiet);

}  // namespace scoleid::io
