#include "solver/needle/held_needle.h"

#include <nlohmann/json.hpp>

#include "core/input_error.h"

namespace needle {

HeldNeedle::HeldNeedle(std::unique_ptr<NeedleModel> inner, double hold_from_ms) : inner_(std::move(inner)), hold_from_ms_(hold_from_ms) {
  NEEDLE_REQUIRE(inner_ != nullptr, "held needle: no needle model to hold");
  NEEDLE_REQUIRE(hold_from_ms >= 0, "held needle: the hold must start at t >= 0");
}

void HeldNeedle::hold() {
  held_ = true;
  time_ms_ = inner_->time_ms();
  still_ = Eigen::MatrixX3d::Zero(inner_->positions_mm().rows(), 3);
  energy_ = inner_->energy();
  reaction_N_ = inner_->drive_reaction_N();  // the drive's at the instant of the hold, until the supports' first step
  taken_mJ_ = energy_.kinetic_mJ;
  energy_.held_mJ += taken_mJ_;  // the supports take the kinetic energy out
  energy_.kinetic_mJ = 0;
}

void HeldNeedle::advance_to(double end_time_ms, NeedleLoads& loads) {
  if (!held_) {
    inner_->advance_to(std::min(end_time_ms, hold_from_ms_), loads);
    if (before_hold(inner_->time_ms())) return;
    hold();
  }
  if (end_time_ms <= time_ms_) return;
  // The loads on the still needle, for the contact's account and the supports' reaction.
  forces_.clear();
  loads.needle_forces(inner_->positions_mm(), still_, end_time_ms, forces_);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& [node, force] : forces_) sum += force;
  reaction_N_ = -sum;
  held_impulse_N_ms_ += (end_time_ms - time_ms_) * reaction_N_;
  time_ms_ = end_time_ms;
}

bool HeldNeedle::speculate_advance(double end_time_ms, NeedleLoads& loads) {
  // advance_to's hold starts at the first span that reaches it: only spans ending before it.
  if (held_ || !before_hold(end_time_ms)) return false;
  return inner_->speculate_advance(end_time_ms, loads);
}

bool HeldNeedle::adopt_speculation(double end_time_ms) {
  if (held_ || !before_hold(end_time_ms)) {
    inner_->adopt_speculation(-1);  // drops any kept one
    return false;
  }
  return inner_->adopt_speculation(end_time_ms);
}

void HeldNeedle::add_summary(nlohmann::json& summary) const {
  inner_->add_summary(summary);
  summary["needle_held"] = {{"from_ms", hold_from_ms_}, {"kinetic_energy_taken_mJ", taken_mJ_}};
}

}  // namespace needle
