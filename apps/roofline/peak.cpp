#include "apps/roofline/peak.hpp"

#include <Eigen/Core>

#include "apps/roofline/best_rate.hpp"

namespace fem::roofline {

namespace {

// Independent multiply-add chains: a multiply-add's latency (4 or 5 cycles on current x86
// cores) times the two units that start one each cycle is 8 to 10 in flight; 12 chains fill
// them with room to spare and still fit AVX2's 16 vector registers.
constexpr int kChains = 12;
constexpr int kRounds = 256;  // multiply-adds per chain per call

// kChains x kRounds multiply-adds on packets of T: acc = acc * a + b, each chain on its own
// register (Eigen's pmadd, Eigen/src/Core/GenericPacketMath.h, is one FMA instruction on a
// target with FMA: the AVX and AVX-512 PacketMath.h). With a < 1 the values stay normal.
template <class T>
struct Chains {
  typename Eigen::internal::packet_traits<T>::type acc[kChains];
};

template <class T>
T fma_chains(Chains<T>& chains) {
  using namespace Eigen::internal;
  using Packet = typename packet_traits<T>::type;
  Packet* acc = chains.acc;
  const Packet a = pset1<Packet>(T(0.999)), b = pset1<Packet>(T(0.001));
  for (int r = 0; r < kRounds; ++r)
    for (int k = 0; k < kChains; ++k) acc[k] = pmadd(acc[k], a, b);
  Packet sum = acc[0];
  for (int k = 1; k < kChains; ++k) sum = padd(sum, acc[k]);
  return predux(sum);
}

template <class T>
double peak_flops(int threads, double seconds, int timings) {
  using Packet = typename Eigen::internal::packet_traits<T>::type;
  constexpr int lanes = Eigen::internal::packet_traits<T>::size;
  // 2 flops per lane per multiply-add.
  const double flops = 2.0 * lanes * kChains * kRounds;
  return best_rate(
      threads, seconds, flops,
      [] {
        Chains<T> chains;
        for (Packet& p : chains.acc) p = Eigen::internal::pset1<Packet>(T(1));
        return chains;
      },
      [](Chains<T>& chains) { return double(fma_chains<T>(chains)); }, timings);
}

}  // namespace

double peak_flops_double(int threads, double seconds, int timings) {
  return peak_flops<double>(threads, seconds, timings);
}
double peak_flops_float(int threads, double seconds, int timings) {
  return peak_flops<float>(threads, seconds, timings);
}

int double_lanes() { return Eigen::internal::packet_traits<double>::size; }
int float_lanes() { return Eigen::internal::packet_traits<float>::size; }
int fma_chains() { return kChains; }

}  // namespace fem::roofline
