// sac/sac.hpp — umbrella header of sac-runtime.
//
// Purpose: one include for a program of the runtime; sac/engine.hpp states the model.
// Invariants: includes only public headers. Complexity: n/a.
// Paper: docs/DESIGN.md, "How it fits together".
#pragma once

#include "sac/chunk_cache.hpp"
#include "sac/engine.hpp"
#include "sac/errors.hpp"
#include "sac/fn.hpp"
#include "sac/hash.hpp"
#include "sac/memory_breakdown.hpp"
#include "sac/mod.hpp"
#include "sac/read_slots.hpp"
#include "sac/stats.hpp"
