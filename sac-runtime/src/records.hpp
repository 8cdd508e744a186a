// records.hpp (private to src/) — decoding a stamp into the trace record it belongs to.
//
// Purpose: the one decoder of stamp kinds, shared by the engine's undo and tear-down
// (engine.cpp), its checker (engine_check.cpp) and its introspection
// (engine_introspection.cpp): a stamp is embedded in its record at a fixed offset, so the
// record is found by subtracting that offset (container_of).
// Invariants: every stamp of the trace but the sentinel and user stamps is embedded in a
// record of the type its kind names (ReadNode, VersionBase, AllocNode, MemoNode).
// Complexity: O(1) per stamp.
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <cstddef>
#include <type_traits>

#include "sac/detail/order_list.hpp"
#include "sac/detail/trace_nodes.hpp"

namespace sac::detail {

/// The record whose stamp at `offset` is s (container_of), const when s is.
template <class N, class S>
N* record_at(S* s, std::size_t offset) {
  using Byte = std::conditional_t<std::is_const_v<S>, const char, char>;
  return reinterpret_cast<N*>(reinterpret_cast<Byte*>(s) - offset);
}

/// A stamp kind as a type: the first argument visit_record passes.
template <StampKind K>
using Kind = std::integral_constant<StampKind, K>;

/// The one decoder of stamp kinds: calls f(Kind<k>{}, record) for k = s->kind(), with the
/// record s belongs to typed by k (ReadNode for ReadStart/ReadEnd, VersionBase for Write,
/// AllocNode for Alloc, MemoNode for MemoStart/MemoEnd; s itself for Sentinel and User),
/// const when s is. f is typically [&]<StampKind K>(Kind<K>, auto* rec) { if constexpr ... }.
template <class S, class F>
void visit_record(S* s, F&& f) {
  constexpr bool c = std::is_const_v<S>;
  using Read = std::conditional_t<c, const ReadNode, ReadNode>;
  using Version = std::conditional_t<c, const VersionBase, VersionBase>;
  using Alloc = std::conditional_t<c, const AllocNode, AllocNode>;
  using Memo = std::conditional_t<c, const MemoNode, MemoNode>;
  switch (s->kind()) {
    case StampKind::ReadStart:
      f(Kind<StampKind::ReadStart>{}, record_at<Read>(s, offsetof(ReadNode, start)));
      break;
    case StampKind::ReadEnd:
      f(Kind<StampKind::ReadEnd>{}, record_at<Read>(s, offsetof(ReadNode, end)));
      break;
    case StampKind::Write:
      f(Kind<StampKind::Write>{}, record_at<Version>(s, offsetof(VersionBase, stamp)));
      break;
    case StampKind::Alloc:
      f(Kind<StampKind::Alloc>{}, record_at<Alloc>(s, offsetof(AllocNode, stamp)));
      break;
    case StampKind::MemoStart:
      f(Kind<StampKind::MemoStart>{}, record_at<Memo>(s, offsetof(MemoNode, start)));
      break;
    case StampKind::MemoEnd:
      f(Kind<StampKind::MemoEnd>{}, record_at<Memo>(s, offsetof(MemoNode, end)));
      break;
    case StampKind::Sentinel:
      f(Kind<StampKind::Sentinel>{}, s);
      break;
    case StampKind::User:
      f(Kind<StampKind::User>{}, s);
      break;
  }
}

}  // namespace sac::detail
