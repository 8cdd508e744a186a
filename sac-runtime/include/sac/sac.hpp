// sac/sac.hpp — umbrella header of sac-runtime. See sac/engine.hpp for the model.
#pragma once

#include "sac/engine.hpp"
#include "sac/errors.hpp"
#include "sac/fn.hpp"
#include "sac/hash.hpp"
#include "sac/mod.hpp"
#include "sac/order_list.hpp"
#include "sac/stamp_queue.hpp"
#include "sac/stats.hpp"
