#include "prescribed_solid_side.hpp"

#include <cmath>
#include <numbers>
#include <optional>

#include "hfmpm/proto/convert.hpp"
#include "hfmpm/solid/prescribed_crack.hpp"

namespace hfmpm::solid {
namespace {

class PrescribedSolidSide final : public coupling::SideModel {
 public:
  void setup(const scene::Scene& scene, const std::string& /*output_dir*/) override {
    if (!scene.solid().has_prescribed_crack()) {
      throw coupling::InputError("this side runs solid.prescribed_crack scenes only");
    }
    const auto& p = scene.solid().prescribed_crack();
    PrescribedCrackConfig config;
    config.mouth = Vec2(p.mouth_x_m(), p.mouth_y_m());
    config.angle_rad = p.angle_deg() * std::numbers::pi / 180.0;
    config.initial_length = p.initial_length_m();
    config.growth_speed = p.growth_speed_m_per_s();
    config.max_length = p.has_max_length_m() ? p.max_length_m() : p.initial_length_m();
    config.spacing = p.spacing_m();
    config.mouth_opening = proto::to_time_function(p.mouth_opening_m());
    config.profile = p.profile() == scene::PrescribedCrack::UNIFORM   ? PrescribedCrackConfig::Profile::Uniform
                     : p.profile() == scene::PrescribedCrack::CHANNEL ? PrescribedCrackConfig::Profile::Channel
                                                                      : PrescribedCrackConfig::Profile::Elliptic;
    config.stable_dt = p.stable_dt_s();
    crack_.emplace(config);
  }
  double stable_dt() const override { return crack_->stable_dt(); }
  void advance(double dt) override { crack_->advance(dt); }
  void publish(protocol::DataFrame& frame) override {
    proto::to_proto(crack_->geometry(), frame.mutable_crack()->add_cracks());
    crack_->clear_grew();  // growth is reported once, in the next publication
  }
  void receive(const protocol::DataFrame& frame) override {
    for (const auto& c : frame.fluid().cracks()) {
      if (c.crack_id() != crack_->geometry().crack_id) {
        throw proto::ProtocolError("FluidState names crack " + std::to_string(c.crack_id()) +
                                   "; this solid has crack " + std::to_string(crack_->geometry().crack_id) + " only");
      }
      try {
        crack_->set_pressure(proto::from_proto(c));
      } catch (const std::invalid_argument& e) {
        throw proto::ProtocolError(std::string("FluidState: ") + e.what());
      }
    }
  }
  SideDiagnostics diagnostics() const override { return crack_->diagnostics(); }

 private:
  std::optional<PrescribedCrack> crack_;
};

}  // namespace

std::unique_ptr<coupling::SideModel> make_prescribed_solid_side() { return std::make_unique<PrescribedSolidSide>(); }

}  // namespace hfmpm::solid
