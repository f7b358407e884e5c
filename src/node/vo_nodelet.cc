// The same node as a nodelet, for zero-copy image transport inside a nodelet manager.
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "hybrid_vo/node/vo_node.h"

namespace hybrid_vo {

class VONodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<VoNode>(getNodeHandle(), getPrivateNodeHandle());
  }
  std::unique_ptr<VoNode> node_;
};

}  // namespace hybrid_vo

PLUGINLIB_EXPORT_CLASS(hybrid_vo::VONodelet, nodelet::Nodelet)
