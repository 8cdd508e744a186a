// The "filter" app: sacapps/filter.hpp behind the uniform App interface.
#include "sacapps/filter.hpp"

#include "app_support.hpp"

namespace sacapps {
namespace {

class FilterApp final : public support::ListApp<List<std::int64_t>> {
 public:
  std::string_view name() const override { return "filter"; }

  void run_conventional() override {
    keep_conventional(filter::filter_conventional<filter::keep>(plain_input()));
  }

  void run_self_adjusting() override {
    run_from_scratch([](sac::Engine& rt, State& s) {
      filter::filter_list<filter::keep>(rt, s.input.head(), &s.out);
    });
  }

  bool verify() override {
    drop_stale();
    const State& s = state();
    return s.out.written() &&
           to_vector(s.out) == filter::filter_conventional<filter::keep>(plain_input()).to_vector();
  }

 protected:
  std::unique_ptr<ListApp> make_empty() const override { return std::make_unique<FilterApp>(); }
};

}  // namespace

std::unique_ptr<App> make_filter() { return std::make_unique<FilterApp>(); }

}  // namespace sacapps
