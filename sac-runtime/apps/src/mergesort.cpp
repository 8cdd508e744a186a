// The "mergesort" app: sacapps/mergesort.hpp behind the uniform App interface.
#include "sacapps/mergesort.hpp"

namespace sacapps {
namespace mergesort {

std::unique_ptr<App> MergesortApp::clone_current() const {
  auto c = std::make_unique<MergesortApp>(range_);
  c->copy_input_from(*this);
  return c;
}

void MergesortApp::sort_self_adjusting(sac::Engine& rt, const List<Value>& in, List<Value>* dst) {
  mergesort(rt, in, dst);
}

const SortCell<SortApp::Value>* MergesortApp::sort_conventional(const SortCell<Value>* in,
                                                                SortArena<Value>& arena) {
  return mergesort_conventional<Value>(in, arena);
}

}  // namespace mergesort

std::unique_ptr<App> make_mergesort() { return std::make_unique<mergesort::MergesortApp>(); }

}  // namespace sacapps
