#include "io/stats.hpp"

#include "garment/stage.hpp"
#include "io/file.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

void FrameStats::add(const StepStats& s) {
  ++steps;
  substeps += s.substeps;
  ms += s.ms;
  couplingContacts += s.couplingContacts;
  emittedParticles += s.emittedParticles;
  removedParticles += s.removedParticles;
  colliderPutBack += s.colliderPutBack;
  densityRatioSum += s.meanDensityRatio;
  fluidIterations += s.fluidIterations;
  fluidIterationsMax = std::max(fluidIterationsMax, s.fluidIterationsMax);
  maxSpeed = std::max(maxSpeed, s.maxSpeed);
  garment += s.garment;
}

WaterMass waterMass(const State& state) {
  WaterMass w;
  const Particles& p = state.particles;
  for (size_t i = 0; i < p.size(); ++i)
    if (isWater(p.phase[i])) w.free += p.mass[i];
  for (double m : state.clothWater) w.heldInCloth += m;
  for (double m : state.clothBuffer) w.inBuffers += m;
  w.emitted = state.ledger.emitted;
  w.removedAtBounds = state.ledger.removedAtBounds;
  w.takenByCloth = state.ledger.takenByCloth;
  w.total = w.free + w.heldInCloth + w.inBuffers + w.removedAtBounds + w.takenByCloth;
  return w;
}

float stateMaxSpeed(const State& state) {
  float m2 = 0.0f;
  for (const Vec3& v : state.particles.v) m2 = std::max(m2, v.squaredNorm());
  return std::sqrt(m2);
}

static nlohmann::ordered_json stageJson(const StageTimes& t) {
  return {{"emit", t.emit},         {"predict", t.predict},     {"neighbors", t.neighbors},
          {"water", t.water},       {"cloth", t.cloth},         {"coupling", t.coupling},
          {"colliders", t.colliders}, {"velocities", t.velocities}, {"wetting", t.wetting},
          {"garment", t.garment},   {"total", t.total}};
}

nlohmann::ordered_json stagePartsJson(const StageTimes& t) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (int k = 0; k < kStagePartCount; ++k) j[kStagePartNames[k]] = t.parts[k];
  return j;
}

nlohmann::ordered_json frameStatsJson(const Model& model, const State& state, int frame, const FrameStats& fs) {
  const Particles& p = state.particles;
  uint64_t water = 0;
  for (size_t i = 0; i < p.size(); ++i) water += isWater(p.phase[i]) ? 1 : 0;
  const WaterMass w = waterMass(state);
  nlohmann::ordered_json j;
  j["frame"] = frame;
  j["time"] = state.time;
  j["step"] = state.stepCount;
  j["steps"] = fs.steps;
  j["substeps"] = fs.substeps;
  j["counts"] = {{"water", water}, {"cloth", model.numCloth}};
  j["waterMass"] = {{"free", w.free},       {"heldInCloth", w.heldInCloth},         {"inBuffers", w.inBuffers},
                    {"emitted", w.emitted}, {"removedAtBounds", w.removedAtBounds},
                    {"takenByCloth", w.takenByCloth}, {"total", w.total}};
  if (model.wetting.enabled)
    j["wetting"] = {{"particlesAbsorbed", state.ledger.particlesAbsorbed},
                    {"dripsEmitted", state.ledger.dripsEmitted},
                    {"dripsHanging", state.dripId.size()}};
  if (model.hasImplicitCloth() || !state.clothWetStart.empty()) {
    const GarmentStats& g = fs.garment;
    uint64_t wet = 0;
    for (float t : state.clothWetStart) wet += std::isfinite(t) ? 1 : 0;
    j["garment"] = {{"solves", g.solves},
                    {"cgIterations", g.cgIterations},
                    {"cgIterationsMax", g.cgIterationsMax},
                    {"cgMaxResidual", g.maxResidual},
                    {"unconvergedSolves", g.unconverged},
                    {"breakdowns", g.breakdowns},
                    {"factorFailures", g.factorFailures},
                    {"contacts", g.contacts},
                    {"contactRows", g.contactRows},
                    {"stickingRows", g.stickingRows},
                    {"edgeContacts", g.edgeContacts},
                    {"selfContacts", g.selfContacts},
                    {"selfEdgeContacts", g.selfEdgeContacts},
                    {"selfReverted", g.selfReverted},
                    {"disturbances", g.disturbances},
                    {"maxStrain", g.maxStrain},
                    {"strainLimited", g.strainLimited},
                    {"halvedSteps", g.halvedSteps},
                    {"dropsTaken", g.dropsTaken},
                    {"dropsTakenTotal", state.ledger.particlesTakenByCloth},
                    {"wetVertices", wet}};
    const GarmentShape shape = garmentShape(model, state);  // how it hangs: wet against dry
    if (shape.vertices > 0) {
      j["garment"]["lowestPoint"] = shape.lowest;
      j["garment"]["meanHeight"] = shape.meanHeight;
      j["garment"]["meanSaturation"] = shape.meanSaturation;
      if (!model.colliders.empty()) j["garment"]["meanColliderDistance"] = shape.meanColliderDistance;
    }
  }
  j["removedAtBounds"] = {{"frame", fs.removedParticles}, {"total", state.ledger.particlesRemovedAtBounds}};
  j["emittedParticles"] = fs.emittedParticles;
  j["couplingContacts"] = fs.couplingContacts;
  j["colliderPutBack"] = fs.colliderPutBack;
  if (fs.steps > 0)
    j["meanDensityRatio"] = fs.densityRatioSum / fs.steps;
  else
    j["meanDensityRatio"] = nullptr;
  if (fs.substeps > 0)
    j["fluidIterations"] = {{"mean", static_cast<double>(fs.fluidIterations) / fs.substeps}, {"max", fs.fluidIterationsMax}};
  j["maxSpeed"] = fs.steps > 0 ? fs.maxSpeed : stateMaxSpeed(state);
  j["ms"] = stageJson(fs.ms);
  j["msParts"] = stagePartsJson(fs.ms);
  j["msPerStep"] = fs.steps > 0 ? fs.ms.total / fs.steps : 0.0;
  return j;
}

JsonLinesWriter::JsonLinesWriter(const std::string& path, bool append)
    : path_(path), out_(append ? openForAppend(path) : openForWrite(path)) {}

void JsonLinesWriter::write(const nlohmann::ordered_json& line) {
  out_ << line.dump() << '\n';
  out_.flush();
  if (!out_) throw Error(path_ + ": write failed");
}

}  // namespace soak
