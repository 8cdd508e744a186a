// sac/sac.hpp — umbrella header of sac-runtime. See sac/engine.hpp for the model.
#pragma once

#include "sac/chunk_cache.hpp"
#include "sac/engine.hpp"
#include "sac/errors.hpp"
#include "sac/fn.hpp"
#include "sac/hash.hpp"
#include "sac/memory_breakdown.hpp"
#include "sac/mod.hpp"
#include "sac/stats.hpp"
