// engine_introspection.cpp — what the engine holds, for people and tools (cold code).
//
// Purpose: Engine::trace_bytes(), Engine::memory_breakdown() and Engine::dump_dot(): the
// trace's memory by record kind and side structure, and the trace as a Graphviz digraph.
// Invariants: reads only; every record is counted once, at its first stamp (a read's or
// memo entry's end stamp is in the same record).
// Complexity: trace_bytes O(1); memory_breakdown and dump_dot O(live events + base
// versions).
// Paper: docs/DESIGN.md, "The runtime".
#include <cstddef>
#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "records.hpp"
#include "sac/engine.hpp"

namespace sac {

using detail::AllocNode;
using detail::Stamp;
using detail::StampKind;
using detail::default_head;
using detail::Kind;
using detail::MemoNode;
using detail::ReaderLink;
using detail::ReadNode;
using detail::VersionBase;
using detail::owner_of;
using detail::visit_record;

std::size_t Engine::trace_bytes() const {
  return record_bytes() + order_.memory_bytes() + queue_.memory_bytes() +
         allocs_.memory_bytes() + memos_.memory_bytes() +
         deferred_.capacity() * sizeof(AllocNode*) + dead_versions_.capacity() * sizeof(VersionBase*) +
         seen_.capacity() * sizeof(Seen);
}

MemoryBreakdown Engine::memory_breakdown() const {
  if (in_computation_) throw UsageError("sac::Engine::memory_breakdown: not inside the computation");
  MemoryBreakdown b;
  // A record of `size` bytes (its ops->size, i.e. sizeof) is a pool block of the size rounded
  // to the grain; the fixed `header` and the `key` come first, the rest is the payload.
  auto block_of = [](std::size_t size) {
    constexpr std::size_t g = detail::Pool::kGrain;
    return size < g ? g : (size + g - 1) & ~(g - 1);
  };
  auto add = [&](RecordBytes& kind, std::size_t size, std::size_t header, std::size_t key) {
    const std::size_t block = block_of(size);
    if (block > detail::Pool::kMaxSmall) b.pool_large += block;
    b.size_class_rounding += block - size;
    ++kind.count;
    kind.header += header;
    kind.key += key;
    kind.payload += block - header - key;
  };
  std::map<std::size_t, std::uint64_t> read_sizes;  // a few closure types: a few sizes
  // Each record once, at its first stamp (a read's or memo entry's end stamp is in the
  // same record).
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        const std::size_t size = read_size(rec);
        const std::size_t header =
            rec->many() ? detail::ReadManyHeader::closure_offset(detail::many_of(rec)->k()) : sizeof(ReadNode);
        add(b.reads, size, header, 0);
        ++read_sizes[block_of(size)];
      } else if constexpr (K == StampKind::Write) {
        add(b.versions, rec->ops()->size, sizeof(VersionBase), 0);
      } else if constexpr (K == StampKind::Alloc) {
        if (rec->ops()->key_equal)
          add(b.keyed_allocs, rec->ops()->size, sizeof(AllocNode),
              reinterpret_cast<const detail::KeyedAllocOps*>(rec->ops())->key_bytes);
        else
          add(b.plain_allocs, rec->ops()->size, sizeof(AllocNode), 0);
      } else if constexpr (K == StampKind::MemoStart) {
        add(b.memos, rec->ops()->size, sizeof(MemoNode), 0);
      }
    });
  }
  for (const VersionBase* v : bases_) add(b.inputs, v->ops()->size, sizeof(VersionBase), 0);
  b.read_sizes.assign(read_sizes.begin(), read_sizes.end());
  b.unaccounted = static_cast<std::int64_t>(record_bytes()) - static_cast<std::int64_t>(b.records());
  b.order_groups = order_.group_count();
  b.order_bytes = order_.memory_bytes();
  b.queue_bytes = queue_.memory_bytes();
  b.alloc_table_bytes = allocs_.memory_bytes();
  b.memo_table_bytes = memos_.memory_bytes();
  b.deferred_bytes = deferred_.capacity() * sizeof(AllocNode*) + dead_versions_.capacity() * sizeof(VersionBase*) +
                     seen_.capacity() * sizeof(Seen);
  b.engine_vectors = bases_.capacity() * sizeof(VersionBase*) + tasks_.capacity() * sizeof(Task) +
                     reruns_.capacity() * sizeof(RerunContext) +
                     pending_.directory_bytes();
  b.pool_reserved = pool_.reserved_bytes();
  return b;
}

void Engine::dump_dot(std::ostream& os) const {
  // Trace tree: reads and memo entries are interior nodes, writes and allocations leaves.
  os << "digraph trace {\n  node [fontname=\"monospace\", fontsize=10];\n  root [label=\"run\"];\n";
  std::vector<std::pair<std::string, const Stamp*>> stack{{"root", nullptr}};
  std::unordered_map<const ModBase*, std::string> mod_names;
  auto mod_name = [&](const ModBase* m) {
    auto it = mod_names.find(m);
    if (it != mod_names.end()) return it->second;
    std::string n = "m" + std::to_string(mod_names.size());
    mod_names.emplace(m, n);
    os << "  " << n << " [shape=box, label=\"" << n << "\"];\n";
    return n;
  };
  // A read does not name its modifiable: find it from the versions' reader lists.
  std::unordered_multimap<const ReadNode*, const ModBase*> read_mod;  // a multi-read: k
  const auto note_list = [&](const ReaderLink* l, const ModBase* m) {
    for (; l; l = l->rnext) read_mod.emplace(owner_of(l), m);
  };
  const auto note_readers = [&](const VersionBase* v) {
    note_list(v->readers, v->mod());
    note_list(v->unordered_readers, v->mod());
  };
  for (const VersionBase* b : bases_) note_readers(b);
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    if (s->kind() == StampKind::Write) note_readers(detail::version_of(const_cast<Stamp*>(s)));
    if (s->kind() == StampKind::ReadStart) {
      ReadNode* r = detail::read_of_start(const_cast<Stamp*>(s));
      const auto note_default = [&](const ReaderLink* l) {
        if (const ModBase* m = default_head(l)) note_list(m->default_readers(), m);
      };
      if (r->many())
        for (std::uint32_t i = 0; i < detail::many_of(r)->k(); ++i) note_default(&detail::many_of(r)->slots()[i].link);
      else
        note_default(&r->link);
    }
  }
  std::size_t id = 0;
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    std::string name = "e" + std::to_string(id++);
    const std::string& parent = stack.back().first;
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        os << "  " << name << " [label=\"read\"];\n  " << parent << " -> " << name << ";\n";
        const auto [lo, hi] = read_mod.equal_range(rec);
        for (auto it = lo; it != hi; ++it)
          os << "  " << mod_name(it->second) << " -> " << name << " [style=dashed];\n";
        stack.push_back({name, &rec->end});
      } else if constexpr (K == StampKind::Write) {
        os << "  " << name << " [shape=diamond, label=\"write\"];\n  " << parent << " -> " << name
           << ";\n  " << name << " -> " << mod_name(rec->mod()) << " [style=dashed];\n";
      } else if constexpr (K == StampKind::Alloc) {
        os << "  " << name << " [shape=note, label=\"alloc\"];\n  " << parent << " -> " << name << ";\n";
      } else if constexpr (K == StampKind::MemoStart) {
        os << "  " << name << " [shape=octagon, label=\"memo\"];\n  " << parent << " -> " << name << ";\n";
        stack.push_back({name, &rec->end});
      }
    });
    while (stack.size() > 1 && stack.back().second == s) stack.pop_back();
  }
  os << "}\n";
}

}  // namespace sac
