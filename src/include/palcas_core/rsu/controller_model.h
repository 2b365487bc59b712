#pragma once
// An RSU controller seen as the model its federation client submits and replaces.

#include "palcas_core/federation/federation_client.h"
#include "palcas_core/rsu/rsu_controller.h"

namespace palcas::rsu {

class ControllerModel : public FederatedModel {
 public:
  /// controller must outlive this adapter.
  explicit ControllerModel(RsuController& controller) : controller_(controller) {}
  bool federationDue() const override { return controller_.federationDue(); }
  uint32_t modelVersion() const override { return controller_.modelVersion(); }
  ModelBlob exportModel() const override { return controller_.exportModel(); }
  uint64_t samplesSinceFederation() const override { return controller_.samplesSinceFederation(); }
  void loadGlobal(const ModelBlob& model, uint32_t version) override {
    controller_.loadGlobalModel(model, version);
  }

 private:
  RsuController& controller_;
};

}  // namespace palcas::rsu
