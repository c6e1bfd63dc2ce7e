// A short, fixed-capacity history of navigation states at the filter's propagation rate, so that
// an aiding measurement valid at an earlier instant t_v (GNSS latency) is compared with the
// navigation solution of that instant (docs/math.md, "Latency").
//
// Static storage, no heap: Capacity entries of 48 bytes in float (32 entries = 1.5 kB: 320 ms
// at a 100 Hz propagation). The angular rate is not stored: the one measurement that needs it
// (the lever-arm term ω × l of the GNSS velocity) takes the current ω, which differs from ω(t_v)
// by ω̇·(now − t_v): 1 cm/s for 0.1 rad/s², 100 ms and a 1 m lever arm, a tenth of a good
// receiver's velocity σ.
// Entries are corrected together with the live solution (shift()), so a state fetched after a
// feedback carries the same correction as the strapdown: an innovation formed against it does not
// count an error twice that an earlier update already removed.
#pragma once

#include <array>
#include <cstdint>

#include "gfins/nav_core/nav_state.hpp"

namespace gfins::nav {

/// The part of a NavState the measurement models need at a past instant (w_b: the current rate).
template <typename T>
struct HistoryEntry {
  std::int64_t t_ns = 0;
  Quat<T> q_nb = Quat<T>::Identity();
  Vec3<T> w_b = Vec3<T>::Zero();
  Vec3<T> v_n = Vec3<T>::Zero();
  Vec3<T> r_n = Vec3<T>::Zero();
};

template <typename T, int Capacity>
class NavHistory {
  static_assert(Capacity >= 2, "interpolation needs two entries");

 public:
  void clear() { size_ = 0; }
  int size() const { return size_; }

  /// Appends the state (oldest dropped when full). Entries must come in increasing t_ns.
  void push(const NavState<T>& s) {
    Stored& e = entries_[static_cast<std::size_t>(head_)];
    e.t_ns = s.t_ns;
    e.q_nb = s.q_nb;
    e.v_n = s.v_n;
    e.r_n = s.r_n;
    head_ = (head_ + 1) % Capacity;
    if (size_ < Capacity) ++size_;
  }

  /// The entry of a NavState (the live solution, for a fix newer than the newest entry).
  static HistoryEntry<T> entry_of(const NavState<T>& s) {
    HistoryEntry<T> e;
    e.t_ns = s.t_ns;
    e.q_nb = s.q_nb;
    e.w_b = s.w_b;
    e.v_n = s.v_n;
    e.r_n = s.r_n;
    return e;
  }

  /// The state at t_ns: interpolated between the stored entries around it, or between the newest
  /// entry and `live` (the current solution) when t_ns is later than every entry; w_b is live's.
  /// Velocity and position are linear in t, the attitude a normalised linear interpolation of the
  /// quaternions (O(Δθ³) from slerp over one propagation step). False when t_ns is older than
  /// the oldest entry or later than `live`.
  bool at(std::int64_t t_ns, const NavState<T>& live, HistoryEntry<T>& out) const {
    const HistoryEntry<T> now = entry_of(live);
    if (t_ns > now.t_ns) return false;
    if (size_ == 0) {
      if (t_ns != now.t_ns) return false;
      out = now;
      return true;
    }
    if (t_ns >= get(size_ - 1).t_ns) {
      out = interpolate(get(size_ - 1), now, t_ns);
      out.w_b = now.w_b;
      return true;
    }
    for (int i = size_ - 1; i > 0; --i) {
      const Stored& a = get(i - 1);
      if (t_ns >= a.t_ns) {
        out = interpolate(a, get(i), t_ns);
        out.w_b = now.w_b;
        return true;
      }
    }
    return false;
  }

  /// Applies the feedback correction of Strapdown::apply_correction (attitude, position,
  /// velocity) to every stored entry.
  void shift(const Vec3<T>& phi_n, const Vec3<T>& dr_n, const Vec3<T>& dv_n) {
    const Quat<T> dq = quat_from_rotation_vector<T>(phi_n);
    for (int i = 0; i < size_; ++i) {
      Stored& e = entries_[static_cast<std::size_t>(i)];
      e.q_nb = dq * e.q_nb;
      e.q_nb.normalize();
      e.r_n -= dr_n;
      e.v_n -= dv_n;
    }
  }

 private:
  struct Stored {
    std::int64_t t_ns = 0;
    Quat<T> q_nb = Quat<T>::Identity();
    Vec3<T> v_n = Vec3<T>::Zero();
    Vec3<T> r_n = Vec3<T>::Zero();
  };

  template <typename A, typename B>
  static HistoryEntry<T> interpolate(const A& a, const B& b, std::int64_t t_ns) {
    const std::int64_t span = b.t_ns - a.t_ns;
    const T w = span > 0 ? from_int64<T>(t_ns - a.t_ns) / from_int64<T>(span) : T(0);
    HistoryEntry<T> out;
    out.t_ns = t_ns;
    out.v_n = a.v_n + w * (b.v_n - a.v_n);
    out.r_n = a.r_n + w * (b.r_n - a.r_n);
    Quat<T> qb = b.q_nb;
    if (a.q_nb.dot(qb) < T(0)) qb.coeffs() = -qb.coeffs();
    out.q_nb.coeffs() = a.q_nb.coeffs() + w * (qb.coeffs() - a.q_nb.coeffs());
    out.q_nb.normalize();
    return out;
  }

  /// i-th entry, 0 = oldest.
  const Stored& get(int i) const {
    const int idx = (head_ - size_ + i + Capacity) % Capacity;
    return entries_[static_cast<std::size_t>(idx)];
  }

  std::array<Stored, Capacity> entries_{};
  int head_ = 0;
  int size_ = 0;
};

}  // namespace gfins::nav
