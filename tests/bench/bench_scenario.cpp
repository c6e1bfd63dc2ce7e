// The benchmarks' samples from host_sim's sample source (bench_scenario.hpp says what and why).
#include "bench_scenario.hpp"

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "gfins/host_sim/sample_generator.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"

namespace gfins::bench {
namespace {

/// The simulated array's errors: Table 6 (scale factors, biases, orientation) and
/// location_error_m(); no noise.
sim::ArrayErrors array_errors() {
  sim::ArrayErrors e = sim::SensorArrayModel::paper_table6();
  for (std::size_t j = 0; j < 6; ++j) e.misalignment.drho_b[j] = location_error_m<double>(j);
  return e;
}

sim::AdcConfig adc_config() {
  sim::AdcConfig c;
  c.sample_rate_hz = kRateHz;
  return c;
}

}  // namespace

double volts_per_count() {
  static const double lsb = sim::make_source_adc(adc_config())->volts_per_count();
  return lsb;
}

Workload make_workload() {
  const auto trajectory = sim::make_maneuver(1.0);
  sim::SensorArrayModel sensors(nav::table1_geometry<double>(kRhoM), array_errors(),
                                nav::GravityModel<double>::constant(nav::kStandardGravity), kRateHz,
                                /*seed=*/1);
  sim::SampleGenerator source(*trajectory, std::move(sensors), sim::make_source_adc(adc_config()),
                              kRateHz);
  Workload w;
  w.samples.reserve(kSamples);
  w.truth.reserve(kSamples);
  for (int k = 0; k < kSamples; ++k) {
    const Result<sim::GeneratedSample> x = source.next();
    if (!x.is_ok()) {
      throw std::runtime_error("bench workload: converter: " + std::string(x.status().message()));
    }
    w.samples.push_back(x->raw);
    w.truth.push_back(sim::to_nav_state<double>(x->truth, x->raw.seq));
  }
  return w;
}

}  // namespace gfins::bench
