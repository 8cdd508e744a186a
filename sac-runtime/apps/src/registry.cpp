// Name -> app factory for the suite and the tests.
#include "sacapps/app.hpp"

namespace sacapps {

const std::vector<std::string>& app_names() {
  static const std::vector<std::string> names{"map",      "filter",    "reverse",   "minimum",
                                              "sum",      "exptrees",  "quicksort", "mergesort",
                                              "quickhull", "diameter"};
  return names;
}

std::unique_ptr<App> make_app(std::string_view name) {
  if (name == "map") return make_map();
  if (name == "filter") return make_filter();
  if (name == "reverse") return make_reverse();
  if (name == "minimum") return make_minimum();
  if (name == "sum") return make_sum();
  if (name == "exptrees") return make_exptrees();
  if (name == "quicksort") return make_quicksort();
  if (name == "mergesort") return make_mergesort();
  if (name == "quickhull") return make_quickhull();
  if (name == "diameter") return make_diameter();
  return nullptr;
}

}  // namespace sacapps
