#include "prescribed_fluid_side.hpp"

#include <optional>

#include "hfmpm/fluid/prescribed_pressure.hpp"
#include "hfmpm/proto/convert.hpp"

namespace hfmpm::fluid {
namespace {

class PrescribedFluidSide final : public coupling::SideModel {
 public:
  void setup(const scene::Scene& scene, const std::string& /*output_dir*/) override {
    if (!scene.fluid().has_prescribed_pressure()) {
      throw coupling::InputError("this side runs fluid.prescribed_pressure scenes only");
    }
    const auto& p = scene.fluid().prescribed_pressure();
    PrescribedPressureConfig config;
    config.inlet_pressure = proto::to_time_function(p.inlet_pressure_pa());
    config.profile = p.profile() == scene::PrescribedPressure::LINEAR ? PrescribedPressureConfig::Profile::Linear
                                                                      : PrescribedPressureConfig::Profile::Uniform;
    config.front_fraction = p.front_fraction();
    config.stable_dt = p.stable_dt_s();
    fluid_.emplace(config);
  }
  double stable_dt() const override { return fluid_->stable_dt(); }
  void advance(double dt) override { fluid_->advance(dt); }
  void publish(protocol::DataFrame& frame) override {
    auto* state = frame.mutable_fluid();  // a FluidState even when there is no crack yet
    for (const auto& p : fluid_->pressures()) proto::to_proto(p, state->add_cracks());
  }
  void receive(const protocol::DataFrame& frame) override {
    std::vector<CrackGeometry> cracks;
    for (const auto& c : frame.crack().cracks()) cracks.push_back(proto::from_proto(c));
    try {
      fluid_->set_geometry(cracks);
    } catch (const std::invalid_argument& e) {
      throw proto::ProtocolError(std::string("CrackState: ") + e.what());
    }
  }
  SideDiagnostics diagnostics() const override { return fluid_->diagnostics(); }

 private:
  std::optional<PrescribedPressure> fluid_;
};

}  // namespace

std::unique_ptr<coupling::SideModel> make_prescribed_fluid_side() { return std::make_unique<PrescribedFluidSide>(); }

}  // namespace hfmpm::fluid
