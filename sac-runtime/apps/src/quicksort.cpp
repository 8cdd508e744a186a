// The "quicksort" app: sacapps/quicksort.hpp behind the uniform App interface.
#include "sacapps/quicksort.hpp"

namespace sacapps {
namespace quicksort {

std::unique_ptr<App> QuicksortApp::clone_current() const {
  auto c = std::make_unique<QuicksortApp>(range_);
  c->copy_input_from(*this);
  return c;
}

void QuicksortApp::sort_self_adjusting(sac::Engine& rt, const List<Value>& in, List<Value>* dst) {
  quicksort(rt, in, dst);
}

const SortCell<SortApp::Value>* QuicksortApp::sort_conventional(const SortCell<Value>* in,
                                                                SortArena<Value>& arena) {
  return quicksort_conventional<Value>(in, nullptr, arena);
}

}  // namespace quicksort

std::unique_ptr<App> make_quicksort() { return std::make_unique<quicksort::QuicksortApp>(); }

}  // namespace sacapps
