// Pool chunk acquisition (kept out of line: it is the cold path).
#include "sac/detail/pool.hpp"

#include <sys/mman.h>

namespace sac::detail {

void Pool::new_chunk() {
  const std::size_t size = next_chunk_;
  void* c = size >= kHugeChunk ? std::aligned_alloc(kHugeChunk, size) : std::malloc(size);
  if (!c) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  if (size >= kHugeChunk) ::madvise(c, size, MADV_HUGEPAGE);  // advisory; failure is harmless
#endif
  chunks_.push_back(c);
  reserved_ += size;
  cur_ = static_cast<char*>(c);
  end_ = cur_ + size;
  if (next_chunk_ < kHugeChunk) next_chunk_ *= 2;
}

}  // namespace sac::detail
