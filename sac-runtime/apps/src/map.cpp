// The "map" app: sacapps/map.hpp behind the uniform App interface.
#include "sacapps/map.hpp"

#include "app_support.hpp"

namespace sacapps {
namespace {

class MapApp final : public support::ListApp<List<std::int64_t>> {
 public:
  std::string_view name() const override { return "map"; }

  void run_conventional() override {
    keep_conventional(map::map_conventional<map::f>(plain_input()));
  }

  void run_self_adjusting() override {
    run_from_scratch([](sac::Engine& rt, State& s) {
      map::map_list<map::f>(rt, s.input.head(), &s.out);
    });
  }

  bool verify() override {
    drop_stale();
    const State& s = state();
    return s.out.written() &&
           to_vector(s.out) == map::map_conventional<map::f>(plain_input()).to_vector();
  }

 protected:
  std::unique_ptr<ListApp> make_empty() const override { return std::make_unique<MapApp>(); }
};

}  // namespace

std::unique_ptr<App> make_map() { return std::make_unique<MapApp>(); }

}  // namespace sacapps
