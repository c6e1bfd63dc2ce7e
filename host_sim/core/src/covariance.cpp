// Covariance propagation and error budget (covariance.hpp).
#include "gfins/host_sim/covariance.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/parallel.hpp"

namespace gfins::sim {
namespace {

using Model = nav::ErrorModel<double, 6>;
using Outputs = Model::Outputs;
using NavPoint = nav::NavState<double>;

/// Two unit vectors spanning the plane ⊥ axis (the first-order directions of an orientation
/// error of a unit sensitive axis).
std::array<Vec3d, 2> perpendicular_basis(const Vec3d& axis) {
  const Vec3d u = axis.normalized();
  const Vec3d pick = std::abs(u.x()) < 0.9 ? Vec3d::UnitX() : Vec3d::UnitY();
  const Vec3d e1 = u.cross(pick).normalized();
  return {e1, u.cross(e1)};
}

/// One deterministic constant parameter: its δs at a point.
struct ConstantParam {
  int kind = 0;  // 0 scale factor, 1 orientation, 2 location
  int sensor = 0;
  Vec3d direction = Vec3d::Zero();  // orientation/location direction times σ
  double sigma = 0;                 // scale factor σ
};

Outputs param_ds(const ConstantParam& p, const NavPoint& x,
                 const nav::ArrayGeometry<double, 6>& g) {
  switch (p.kind) {
    case 0:
      return nav::scale_factor_ds<double, 6>(x, g, p.sensor, p.sigma);
    case 1:
      return nav::orientation_ds<double, 6>(x, g, p.sensor, p.direction);
    default:
      return nav::location_ds<double, 6>(x, g, p.sensor, p.direction);
  }
}

std::vector<ConstantParam> constant_params(const CovarianceSpec& s) {
  std::vector<ConstantParam> out;
  for (int j = 0; j < 6; ++j) {
    const auto sj = static_cast<std::size_t>(j);
    if (s.constants.scale_factor_sigma[sj] > 0) {
      out.push_back({0, j, Vec3d::Zero(), s.constants.scale_factor_sigma[sj]});
    }
    if (s.constants.orientation_sigma_rad[sj] > 0) {
      for (const Vec3d& e : perpendicular_basis(s.geometry.theta_b[sj])) {
        out.push_back({1, j, e * s.constants.orientation_sigma_rad[sj], 0});
      }
    }
    if (s.constants.location_sigma_m[sj] > 0) {
      for (int a = 0; a < 3; ++a) {
        out.push_back({2, j, Vec3d::Unit(a) * s.constants.location_sigma_m[sj], 0});
      }
    }
  }
  return out;
}

void check(const Status& st) {
  if (!st.is_ok()) throw std::invalid_argument(st.message());
}

bool has_noise(const nav::SensorNoiseSpec<double>& n) {
  for (std::size_t j = 0; j < 6; ++j) {
    if (n.white_sigma_mps2[j] != 0 || n.bias_rw_mps2_sqrt_s[j] != 0) return true;
  }
  return false;
}

}  // namespace

nav::NavState<double> truth_nav_state(const TruthState& x, const nav::GravityModel<double>& g) {
  NavPoint s = to_nav_state<double>(x);
  s.f_b = x.q_nb.conjugate() * (x.a_n - g.g_n(x.r_n));  // what to_nav_state cannot know
  return s;
}

CovarianceResult propagate_covariance(const CovarianceSpec& spec) {
  if (spec.trajectory == nullptr) throw std::invalid_argument("covariance: no trajectory");
  if (!(spec.dt_s > 0) || !std::isfinite(spec.dt_s) || !(spec.duration_s >= 0)) {
    throw std::invalid_argument("covariance: dt_s must be positive and duration_s non-negative");
  }
  const auto solver = nav::ArraySolver<double, 6>::create(spec.geometry);
  check(solver.status());
  const Model model(solver.value(), spec.gravity);
  const std::size_t decimation = spec.decimation == 0 ? 1 : spec.decimation;
  const auto steps = static_cast<std::size_t>(std::llround(spec.duration_s / spec.dt_s));
  const std::vector<ConstantParam> params = constant_params(spec);

  Model::StateMat p = Model::initial_covariance(spec.noise);
  // Without a stochastic source P starts at 0 and Q_d is 0 at every step, so P stays exactly 0
  // (Φ 0 Φᵀ + 0): the budget's deterministic sources skip its propagation.
  const bool stochastic = !p.isZero(0.0) || has_noise(spec.noise);
  std::vector<Model::StateVec> xs(params.size(), Model::StateVec::Zero());
  CovarianceResult r;
  const auto record = [&](double t) {
    r.t_s.push_back(t);
    for (std::size_t i = 0; i < 12; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      double var = p(ii, ii);
      for (const auto& x : xs) var += x(ii) * x(ii);
      r.sigma[i].push_back(std::sqrt(std::max(var, 0.0)));
    }
  };
  NavPoint x0 = truth_nav_state(spec.trajectory->at(0.0), spec.gravity);
  record(0.0);
  for (std::size_t k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * spec.dt_s;
    const NavPoint x1 = truth_nav_state(spec.trajectory->at(t), spec.gravity);
    // One Φ per step for P and every constant parameter (the sources share the truth).
    const auto phi = model.transition(x0, x1, spec.dt_s);
    check(phi.status());
    if (stochastic)
      check(model.propagate_covariance(phi.value(), x0, x1, spec.noise, spec.dt_s, p));
    for (std::size_t i = 0; i < params.size(); ++i) {
      model.propagate(phi.value(), x0, x1, spec.dt_s, param_ds(params[i], x0, spec.geometry),
                      param_ds(params[i], x1, spec.geometry), xs[i]);
    }
    if (k % decimation == 0 || k == steps) record(t);
    x0 = x1;
  }
  return r;
}

CovarianceReport covariance_report(const CovarianceSpec& spec, const std::vector<double>& times_s,
                                   std::size_t jobs) {
  // specs[0] is the whole spec (the envelopes and the budget's "total"), specs[1 + s] source
  // group s alone.
  std::vector<CovarianceSpec> specs(kBudgetSources.size() + 1);
  specs[0] = spec;
  for (std::size_t s = 0; s < kBudgetSources.size(); ++s) {
    CovarianceSpec c = spec;
    c.noise = {};
    c.constants = {};
    switch (s) {
      case 0:
        c.noise.bias_sigma_mps2 = spec.noise.bias_sigma_mps2;
        break;
      case 1:
        c.noise.bias_rw_mps2_sqrt_s = spec.noise.bias_rw_mps2_sqrt_s;
        break;
      case 2:
        c.noise.white_sigma_mps2 = spec.noise.white_sigma_mps2;
        break;
      case 3:
        c.constants.scale_factor_sigma = spec.constants.scale_factor_sigma;
        break;
      case 4:
        c.constants.orientation_sigma_rad = spec.constants.orientation_sigma_rad;
        break;
      default:
        c.constants.location_sigma_m = spec.constants.location_sigma_m;
        break;
    }
    specs[s + 1] = c;
  }
  // Jobs longest first, so that the threads finish close together (list scheduling): the whole
  // spec, the three sources with P (each a P propagation: about half the whole), then location,
  // orientation and scale factor (18, 12 and 6 parameters). Measured on the manoeuvre with every
  // source (2 s at 1 kHz): 27, 13, 13, 13, 10, 8, 5 ms, so two threads split 44 + 44.
  constexpr std::array<std::size_t, 7> kJobSpec = {0, 1, 2, 3, 6, 5, 4};
  static_assert(kJobSpec.size() == kBudgetSources.size() + 1);
  CovarianceReport out;
  std::vector<std::vector<std::array<double, 12>>> at_times(specs.size());
  // Each propagation depends on its spec only and lands in its own slot: nothing is summed
  // across jobs, so any thread count gives the same bits (parallel.hpp).
  ordered_parallel_for(
      specs.size(), jobs,
      [&](std::size_t job) { return propagate_covariance(specs[kJobSpec[job]]); },
      [&](std::size_t job, CovarianceResult&& r) {
        const std::size_t j = kJobSpec[job];
        std::vector<std::array<double, 12>> at;
        for (const double t : times_s) {
          std::size_t best = 0;
          for (std::size_t k = 1; k < r.t_s.size(); ++k) {
            if (std::abs(r.t_s[k] - t) < std::abs(r.t_s[best] - t)) best = k;
          }
          if (j == 0) out.budget.t_s.push_back(r.t_s.empty() ? t : r.t_s[best]);
          std::array<double, 12> row{};
          for (std::size_t i = 0; i < 12; ++i) row[i] = r.sigma[i].empty() ? 0 : r.sigma[i][best];
          at.push_back(row);
        }
        at_times[j] = std::move(at);
        if (j == 0) out.envelopes = std::move(r);
        return true;
      });
  // Budget order: the sources of kBudgetSources, then "total".
  for (std::size_t s = 1; s < specs.size(); ++s) out.budget.sigma.push_back(std::move(at_times[s]));
  out.budget.sigma.push_back(std::move(at_times[0]));
  return out;
}

ErrorBudget error_budget(const CovarianceSpec& spec, const std::vector<double>& times_s,
                         std::size_t jobs) {
  return covariance_report(spec, times_s, jobs).budget;
}

HostStatus write_covariance_csv(const CovarianceResult& r, const std::string& path) {
  std::ofstream out(path);
  if (!out) return HostError{ErrorCode::kIoError, "covariance: cannot open " + path};
  out << "t_s";
  for (const char* n : kErrorStateNames) out << ",sigma_" << n;
  out << '\n';
  out.precision(9);
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    out << r.t_s[k];
    for (std::size_t i = 0; i < 12; ++i) out << ',' << r.sigma[i][k];
    out << '\n';
  }
  out.close();
  if (!out) return HostError{ErrorCode::kIoError, "covariance: write failed: " + path};
  return Done{};
}

HostStatus write_budget_csv(const ErrorBudget& b, const std::string& path) {
  std::ofstream out(path);
  if (!out) return HostError{ErrorCode::kIoError, "covariance: cannot open " + path};
  out << "source,t_s";
  for (const char* n : kErrorStateNames) out << ",sigma_" << n;
  out << '\n';
  out.precision(9);
  for (std::size_t s = 0; s < b.sigma.size(); ++s) {
    const std::string name = s < kBudgetSources.size() ? kBudgetSources[s] : "total";
    for (std::size_t k = 0; k < b.t_s.size(); ++k) {
      out << name << ',' << b.t_s[k];
      for (std::size_t i = 0; i < 12; ++i) out << ',' << b.sigma[s][k][i];
      out << '\n';
    }
  }
  out.close();
  if (!out) return HostError{ErrorCode::kIoError, "covariance: write failed: " + path};
  return Done{};
}

}  // namespace gfins::sim
