// MikkTSpace, written from the algorithm (see mikktspace.hpp for the outline and the references).
//
// Naming: a "slot" is one corner of one input face; a "tri" is one triangle of the split faces.
// Triangle arrays are indexed in "work order": the good triangles first, in input order, then the
// degenerate ones. Everything that runs in parallel writes disjoint outputs, and every choice that
// depends on order is made in a fixed order, so 1 and N threads give the same bits.

#include "frames/mikktspace.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <new>
#include <span>
#include <type_traits>
#include <utility>


#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "sgbake/core/math.hpp"

namespace sgbake::mikk {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::int32_t kNoTri = -1;

// Triangle flags.
constexpr std::uint8_t kDegenerate = 1;        // two corners share a position
constexpr std::uint8_t kQuadOneDegenerate = 2;  // one half of a quad whose other half is degenerate
constexpr std::uint8_t kGroupWithAny = 4;      // no usable UV derivative: joins any group
constexpr std::uint8_t kOrientPreserving = 8;  // positive UV area

// Parallel loops over this many items or fewer run inline; chunks are at least this big.
constexpr std::size_t kGrain = 2048;

// Stable sort for the short runs this algorithm sorts (edges at a vertex, triangles of a group);
// falls back to std::stable_sort for long ones.
template <class It, class Less>
void insertionSortStable(It begin, It end, Less less) {
  constexpr std::ptrdiff_t kShortRun = 32;
  if (end - begin > kShortRun) {
    std::stable_sort(begin, end, less);
    return;
  }
  for (It i = begin + (begin != end); i < end; ++i) {
    auto value = *i;
    It j = i;
    for (; j != begin && less(value, *(j - 1)); --j) *j = *(j - 1);
    *j = value;
  }
}

template <class F>
void parallelFor(std::size_t n, F&& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
}

// Work arrays are not initialized: every array is written in full (by parallel loops, which
// also spread the first touch of fresh memory over the threads) before it is read.
// (Transparent huge pages were tried: on this project's VMs the kernel's compaction made
// first touches slower, not faster.)
void* allocateLarge(std::size_t bytes) { return ::operator new(bytes); }

void freeLarge(void* p, std::size_t /*bytes*/) { ::operator delete(p); }


template <class T>
class ParallelArray {
  // The elements (plain numbers and aggregates of them) are created implicitly by the allocation
  // and given their values by the first write.
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  ParallelArray() = default;
  explicit ParallelArray(std::size_t n) { resize(n); }
  ParallelArray(const ParallelArray&) = delete;
  ParallelArray& operator=(const ParallelArray&) = delete;
  ParallelArray(ParallelArray&& other) noexcept { swap(other); }
  ParallelArray& operator=(ParallelArray&& other) noexcept {
    swap(other);
    return *this;
  }
  ~ParallelArray() { release(); }

  void resize(std::size_t n) {
    release();
    data_ = static_cast<T*>(allocateLarge(n * sizeof(T)));
    size_ = n;
  }
  void fill(const T& value) {
    parallelFor(size_, [&](std::size_t i) { data_[i] = value; });
  }
  std::size_t size() const { return size_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

 private:
  void swap(ParallelArray& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
  }
  void release() {
    if (data_ != nullptr) freeLarge(data_, size_ * sizeof(T));
    data_ = nullptr;
    size_ = 0;
  }
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Grouping items by key in parallel.

// A stable counting sort of the items 0..n-1 by key(i) < numKeys, in parallel. On return,
// items[start[k]..start[k+1]) are the items with key k, ascending. Two passes: items are first
// partitioned by the key's top bits (fixed blocks of items each count and scatter their own, so
// the result does not depend on the number of threads), then each partition sorts its items by
// the full key on its own, with a count array small enough to stay in cache.
template <class KeyFn>
void sortByKey(std::size_t n, std::size_t numKeys, KeyFn key, ParallelArray<std::uint32_t>& start,
               ParallelArray<std::uint32_t>& items) {
  constexpr std::size_t kBlock = 16384;
  constexpr int kPartitionBits = 8;
  const std::size_t maxKey = numKeys > 0 ? numKeys - 1 : 0;
  int shift = 0;  // partition = key >> shift, below 2^kPartitionBits
  while ((maxKey >> shift) >> kPartitionBits) ++shift;
  const std::size_t numParts = (maxKey >> shift) + 1;
  const std::size_t numBlocks = (n + kBlock - 1) / kBlock;
  start.resize(numKeys + 1);
  items.resize(n);
  start[numKeys] = static_cast<std::uint32_t>(n);
  if (n == 0) {
    parallelFor(numKeys, [&](std::size_t k) { start[k] = 0; });
    return;
  }
  // Pass 1: per block, the count of each partition, then each block's first position in it.
  std::vector<std::uint32_t> offset(numBlocks * numParts, 0);
  tbb::parallel_for(std::size_t{0}, numBlocks, [&](std::size_t b) {
    std::uint32_t* count = offset.data() + b * numParts;
    for (std::size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) ++count[key(i) >> shift];
  });
  std::vector<std::uint32_t> partStart(numParts + 1);
  std::uint32_t sum = 0;
  for (std::size_t p = 0; p < numParts; ++p) {
    partStart[p] = sum;
    for (std::size_t b = 0; b < numBlocks; ++b) {
      const std::uint32_t count = offset[b * numParts + p];
      offset[b * numParts + p] = sum;
      sum += count;
    }
  }
  partStart[numParts] = sum;
  // (key, item) pairs, so that pass 2 reads keys sequentially.
  ParallelArray<std::uint64_t> partitioned(n);
  tbb::parallel_for(std::size_t{0}, numBlocks, [&](std::size_t b) {
    std::uint32_t* next = offset.data() + b * numParts;
    for (std::size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) {
      const std::uint32_t k = key(i);
      partitioned[next[k >> shift]++] = (std::uint64_t{k} << 32) | i;
    }
  });
  // Pass 2: each partition by the full key.
  tbb::parallel_for(std::size_t{0}, numParts, [&](std::size_t p) {
    const std::size_t firstKey = p << shift, endKey = std::min(numKeys, (p + 1) << shift);
    std::vector<std::uint32_t> next(endKey - firstKey, 0);
    const std::uint32_t begin = partStart[p], end = partStart[p + 1];
    for (std::uint32_t j = begin; j < end; ++j) ++next[(partitioned[j] >> 32) - firstKey];
    std::uint32_t position = begin;
    for (std::size_t k = firstKey; k < endKey; ++k) {
      start[k] = position;
      const std::uint32_t count = next[k - firstKey];
      next[k - firstKey] = position;
      position += count;
    }
    for (std::uint32_t j = begin; j < end; ++j) {
      const std::uint64_t v = partitioned[j];
      items[next[(v >> 32) - firstKey]++] = static_cast<std::uint32_t>(v);
    }
  });
}

// ---------------------------------------------------------------------------------------------
// Welding: rep[s] = the smallest slot whose position, normal and UV equal slot s's exactly.

std::uint32_t canonicalBits(float x) {
  return x == 0.0f ? 0u : std::bit_cast<std::uint32_t>(x);  // -0 and +0 weld, as float == does
}

std::uint64_t mix(std::uint64_t h, std::uint32_t w) {
  h ^= w;
  h *= 0xbf58476d1ce4e5b9ull;
  return h ^ (h >> 29);
}

// Welding keys: float bits with -0 folded onto +0.
template <std::size_t N>
using Key = std::array<std::uint32_t, N>;

template <std::size_t N>
Key<N> keyOf(std::initializer_list<float> values) {
  Key<N> key{};
  std::size_t i = 0;
  for (float x : values) key[i++] = canonicalBits(x);
  return key;
}

// What welding compares: position, normal and UV.
Key<8> weldKey(const Input& in, std::size_t s) {
  const Vec3f p = in.position[in.vertex[s]], n = in.normal[s];
  const Vec2f t = in.uv[s];
  return keyOf<8>({p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y});
}

// What welding compares of slots at one position: normal and UV.
Key<5> attributeKey(const Input& in, std::size_t s) {
  const Vec3f n = in.normal[s];
  const Vec2f t = in.uv[s];
  return keyOf<5>({n.x, n.y, n.z, t.x, t.y});
}

template <std::size_t N>
std::uint64_t hashKey(const Key<N>& key) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::uint32_t w : key) h = mix(h, w);
  return h ^ (h >> 32);
}

// rep[i] = the smallest j <= i with key(j) == key(i), for i < n.
template <class KeyFn>
ParallelArray<std::uint32_t> weldByHash(std::size_t n, KeyFn key) {
  using K = decltype(key(std::size_t{0}));
  ParallelArray<std::uint64_t> hash(n);
  parallelFor(n, [&](std::size_t s) { hash[s] = hashKey(key(s)); });

  // Partition items by the top bits of their hash (each bucket lists its items in ascending
  // order), then weld each bucket with its own small hash table over a copy of its keys, so that
  // a bucket touches only its own memory.
  constexpr int kBucketBits = 8;
  constexpr std::size_t kBuckets = std::size_t{1} << kBucketBits;
  ParallelArray<std::uint32_t> bucketStart, order;
  sortByKey(n, kBuckets, [&](std::size_t s) { return static_cast<std::uint32_t>(hash[s] >> (64 - kBucketBits)); },
            bucketStart, order);

  ParallelArray<std::uint32_t> rep(n);
  tbb::parallel_for(std::size_t{0}, kBuckets, [&](std::size_t b) {
    const std::uint32_t begin = bucketStart[b], size = bucketStart[b + 1] - begin;
    if (size == 0) return;
    std::vector<K> keys(size);
    for (std::uint32_t k = 0; k < size; ++k) keys[k] = key(order[begin + k]);
    const std::size_t capacity = std::bit_ceil(std::size_t{2} * size);
    const std::size_t mask = capacity - 1;
    struct Entry {
      std::uint64_t hash;
      std::uint32_t first = kNone;  // bucket-local index of the first item of a distinct key
    };
    std::vector<Entry> table(capacity);
    for (std::uint32_t k = 0; k < size; ++k) {
      const std::uint32_t s = order[begin + k];
      const std::uint64_t h = hash[s];
      for (std::size_t pos = h & mask;; pos = (pos + 1) & mask) {
        Entry& entry = table[pos];
        if (entry.first == kNone) {
          entry = {h, k};
          rep[s] = s;
          break;
        }
        if (entry.hash == h && keys[entry.first] == keys[k]) {
          rep[s] = order[begin + entry.first];  // ascending order: the first is the smallest
          break;
        }
      }
    }
  });
  return rep;
}

// Welding with vertex ids: positions are compared once per vertex (vertices at one position form
// a class), and each slot is compared (normal and UV) only with the slots of its class, a handful
// on most meshes.
ParallelArray<std::uint32_t> weldByVertex(const Input& in) {
  const std::size_t n = in.numSlots(), nv = in.position.size();
  ParallelArray<std::uint32_t> vertexStart, vertexSlots;  // each vertex's slots, ascending
  sortByKey(n, nv, [&](std::size_t s) { return in.vertex[s]; }, vertexStart, vertexSlots);
  // Position classes: the smallest vertex at the same position.
  const ParallelArray<std::uint32_t> positionClass = weldByHash(nv, [&](std::size_t u) {
    const Vec3f p = in.position[u];
    return keyOf<3>({p.x, p.y, p.z});
  });
  // The vertices that are not the first of their class, as (class, vertex), by class (rare).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> joined;
  for (std::uint32_t u = 0; u < nv; ++u)
    if (positionClass[u] != u) joined.emplace_back(positionClass[u], u);
  std::stable_sort(joined.begin(), joined.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  // Within a class, each slot welds to the first earlier slot with the same normal and UV.
  ParallelArray<std::uint32_t> rep(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    constexpr std::uint32_t kLinearScan = 32;  // longer classes sort their keys instead
    std::vector<std::pair<Key<5>, std::uint32_t>> sorted;
    std::vector<std::uint32_t> merged;
    for (std::size_t u = r.begin(); u != r.end(); ++u) {
      if (positionClass[u] != u) continue;  // welded with its class
      std::span<const std::uint32_t> slots(vertexSlots.begin() + vertexStart[u], vertexSlots.begin() + vertexStart[u + 1]);
      const auto others = std::equal_range(joined.begin(), joined.end(), std::pair{static_cast<std::uint32_t>(u), 0u},
                                           [](const auto& a, const auto& b) { return a.first < b.first; });
      if (others.first != others.second) {
        merged.assign(slots.begin(), slots.end());
        for (auto o = others.first; o != others.second; ++o)
          merged.insert(merged.end(), vertexSlots.begin() + vertexStart[o->second], vertexSlots.begin() + vertexStart[o->second + 1]);
        std::sort(merged.begin(), merged.end());
        slots = merged;
      }
      const auto size = static_cast<std::uint32_t>(slots.size());
      if (size <= kLinearScan) {
        std::array<Key<5>, kLinearScan> keys;
        for (std::uint32_t k = 0; k < size; ++k) {
          keys[k] = attributeKey(in, slots[k]);
          std::uint32_t j = 0;
          while (keys[j] != keys[k]) ++j;  // stops at k at the latest
          rep[slots[k]] = slots[j];        // ascending order: the first is the smallest
        }
        continue;
      }
      sorted.clear();
      for (const std::uint32_t slot : slots) sorted.emplace_back(attributeKey(in, slot), slot);
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t k = 0; k < sorted.size(); ++k) {
        const bool sameAsPrevious = k > 0 && sorted[k - 1].first == sorted[k].first;
        rep[sorted[k].second] = sameAsPrevious ? rep[sorted[k - 1].second] : sorted[k].second;
      }
    }
  });
  return rep;
}

// rep[s] = the smallest slot whose position, normal and UV equal slot s's exactly. Both ways
// give the same result; vertex ids pay off when vertices are shared by several corners.
ParallelArray<std::uint32_t> weld(const Input& in) {
  const bool shared = std::size_t{2} * in.position.size() <= in.numSlots();
  if (shared) return weldByVertex(in);
  return weldByHash(in.numSlots(), [&](std::size_t s) { return weldKey(in, s); });
}

// ---------------------------------------------------------------------------------------------
// Per-triangle state. Triangle corners are numbered 3 * triangle + corner; edge i of a triangle
// runs from its corner i to corner i+1 and has the number of corner i.

struct Tri {
  std::int32_t face = 0;                 // input face
  std::array<std::uint8_t, 3> corner{};  // corner i = face corner
  std::uint8_t flags = 0;
};

// A good triangle's unit dP/ds and dP/dt (sign-corrected), or zero where unusable.
struct TriFrame {
  Vec3f os, ot;
};

// What the group evaluation reads of a good triangle corner: its triangle's TriFrame projected
// into the tangent plane of the corner's normal and normalized again (or zero), and the interior
// angle at the corner in that plane. Computed once per corner, in the per-triangle pass.
struct CornerFrame {
  Vec3f os, ot;
  float angle;
};

constexpr std::uint32_t next(std::uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }  // corner/edge
constexpr std::uint32_t prev(std::uint32_t c) { return c % 3 == 0 ? c + 2 : c - 1; }

// The frame the algorithm keeps per vertex also carries dP/dt and the derivatives' magnitudes.
// sgbake outputs the tangent and its sign only, so it keeps the tangent alone: the one place the
// rest would matter is averaging the two frames of a quad-diagonal corner, where frames with
// equal tangents but different magnitudes average to the same tangent up to the last bit.
Vec3f average(Vec3f a, Vec3f b) { return a == b ? a : normalizeIfNotZero(a + b); }

// What sub-grouping and averaging read of a triangle of a group, at the group's vertex.
struct Member {
  Vec3f os, ot;          // dP/ds, dP/dt projected into the vertex's tangent plane, unit or zero
  float angle;           // interior angle at the vertex
  std::int32_t face;     // input face
  bool any;              // "group with any"
};

// Four floats at once, for the per-corner projections of the per-triangle pass: SSE2 where the
// compiler targets it (every x86-64), plain arrays elsewhere. Every operation is the IEEE
// operation the scalar code performs, lane by lane (SSE's sqrt and division are correctly
// rounded like the scalar ones), so the results are the same bits as the scalar functions'.
struct Float4 {
#if defined(__SSE2__)
  __m128 v;
  static Float4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  void store(float* p) const { _mm_storeu_ps(p, v); }
  static Float4 all(float x) { return {_mm_set1_ps(x)}; }
  friend Float4 operator+(Float4 a, Float4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend Float4 operator-(Float4 a, Float4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend Float4 operator*(Float4 a, Float4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend Float4 operator/(Float4 a, Float4 b) { return {_mm_div_ps(a.v, b.v)}; }
  friend Float4 sqrt(Float4 a) { return {_mm_sqrt_ps(a.v)}; }
  // Lanes where |a| > b, as a mask for select().
  friend Float4 absGreater(Float4 a, Float4 b) { return {_mm_cmpgt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v), b.v)}; }
  friend Float4 operator|(Float4 a, Float4 b) { return {_mm_or_ps(a.v, b.v)}; }
  // Per lane: mask ? a : b.
  friend Float4 select(Float4 mask, Float4 a, Float4 b) { return {_mm_or_ps(_mm_and_ps(mask.v, a.v), _mm_andnot_ps(mask.v, b.v))}; }
#else
  std::array<float, 4> v;
  template <class F>
  static Float4 map(F f) {
    Float4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = f(i);
    return r;
  }
  static Float4 load(const float* p) { return map([&](int i) { return p[i]; }); }
  void store(float* p) const { std::copy(v.begin(), v.end(), p); }
  static Float4 all(float x) { return map([&](int) { return x; }); }
  friend Float4 operator+(Float4 a, Float4 b) { return map([&](int i) { return a.v[i] + b.v[i]; }); }
  friend Float4 operator-(Float4 a, Float4 b) { return map([&](int i) { return a.v[i] - b.v[i]; }); }
  friend Float4 operator*(Float4 a, Float4 b) { return map([&](int i) { return a.v[i] * b.v[i]; }); }
  friend Float4 operator/(Float4 a, Float4 b) { return map([&](int i) { return a.v[i] / b.v[i]; }); }
  friend Float4 sqrt(Float4 a) { return map([&](int i) { return std::sqrt(a.v[i]); }); }
  friend Float4 absGreater(Float4 a, Float4 b) { return map([&](int i) { return std::abs(a.v[i]) > b.v[i] ? 1.0f : 0.0f; }); }
  friend Float4 operator|(Float4 a, Float4 b) { return map([&](int i) { return a.v[i] != 0 || b.v[i] != 0 ? 1.0f : 0.0f; }); }
  friend Float4 select(Float4 mask, Float4 a, Float4 b) { return map([&](int i) { return mask.v[i] != 0 ? a.v[i] : b.v[i]; }); }
#endif
};

struct Vec3x4 {
  Float4 x, y, z;
};

[[gnu::always_inline]] inline Float4 dot(Vec3x4 a, Vec3x4 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// v projected into the plane orthogonal to the unit vector n, then normalized unless zero
// (MikkTSpace's normalizeIfNotZero(v - dot(n, v) * n)), on four vectors. Inlined, so that the
// vectors stay in registers.
[[gnu::always_inline]] inline Vec3x4 projectNormalized(Vec3x4 v, Vec3x4 n) {
  const Float4 d = dot(n, v);
  const Vec3x4 p{v.x - d * n.x, v.y - d * n.y, v.z - d * n.z};
  const Float4 tiny = Float4::all(std::numeric_limits<float>::min());
  const Float4 notZero = absGreater(p.x, tiny) | absGreater(p.y, tiny) | absGreater(p.z, tiny);
  const Float4 inverseLength = Float4::all(1.0f) / sqrt(dot(p, p));
  return {select(notZero, inverseLength * p.x, p.x), select(notZero, inverseLength * p.y, p.y),
          select(notZero, inverseLength * p.z, p.z)};
}

float uvArea2(const Input& in, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const Vec2f t1 = in.uv[a], t2 = in.uv[b], t3 = in.uv[c];
  const float t21x = t2.x - t1.x, t21y = t2.y - t1.y;
  const float t31x = t3.x - t1.x, t31y = t3.y - t1.y;
  return t21x * t31y - t21y * t31x;
}

class Engine {
 public:
  Engine(const Input& in, const Output& out) : in_(in), out_(out) {}

  void run() {
    rep_ = weld(in_);
    splitFaces();
    initTriangles();
    unifyQuadOrientation();
    // Triangle corners by welded vertex, each vertex's in ascending order.
    sortByKey(3 * numGood_, in_.numSlots(), [&](std::size_t c) { return vert_[c]; }, vertexStart_, vertexCorners_);
    bool anyGroupWithAny = false;
    for (std::size_t t = 0; t < numGood_ && !anyGroupWithAny; ++t)
      anyGroupWithAny = tris_[t].flags & kGroupWithAny;
    if (anyGroupWithAny) {
      findNeighbors();
      buildAndEvaluateGroupsSerially();
    } else {
      buildAndEvaluateGroupsPerVertex();
    }
    copyToDegenerate();
  }

 private:
  Vec3f position(std::size_t slot) const { return in_.position[in_.vertex[slot]]; }

  // Steps 3 and 4: split faces into triangles, written straight into work order (good triangles
  // in input order, then degenerate ones in input order). Slots in no good triangle get the
  // algorithm's default frame (tangent +x, orientation reversed), which copyToDegenerate may
  // replace; all other slots are written by the group evaluation.
  void splitFaces() {
    const std::size_t nf = in_.faceStart.size() - 1;
    // Per face: bit 0 = quad split on 0-2, bits 1/2 = first/second triangle degenerate,
    // bits 3/4 = first/second triangle exists.
    std::vector<std::uint8_t> shape(nf);
    parallelFor(nf, [&](std::size_t f) {
      const std::uint32_t s0 = in_.faceStart[f], n = in_.faceStart[f + 1] - s0;
      if (n != 3 && n != 4) return;  // a face gather skipped: no slots
      const bool on02 = n == 3 || quadSplitsOn02(s0);
      const auto corners = triangleCorners(n, on02);
      std::uint8_t code = on02 ? 1 : 0;
      for (std::uint32_t k = 0; k < (n == 4 ? 2u : 1u); ++k) {
        code |= static_cast<std::uint8_t>(8u << k);
        if (isDegenerate(s0, corners[k])) code |= static_cast<std::uint8_t>(2u << k);
      }
      shape[f] = code;
    });
    // Exclusive prefix counts of good and degenerate triangles per face.
    goodStart_.resize(nf + 1);
    std::vector<std::uint32_t> degenerateStart(nf + 1);
    goodStart_[0] = degenerateStart[0] = 0;
    for (std::size_t f = 0; f < nf; ++f) {
      std::uint32_t good = 0, bad = 0;
      for (unsigned k = 0; k < 2; ++k) {
        if (!(shape[f] & (8u << k))) continue;
        (shape[f] & (2u << k)) ? ++bad : ++good;
      }
      goodStart_[f + 1] = goodStart_[f] + good;
      degenerateStart[f + 1] = degenerateStart[f] + bad;
    }
    numGood_ = goodStart_[nf];
    const std::size_t nt = numGood_ + degenerateStart[nf];
    tris_.resize(nt);
    slot_.resize(3 * nt);
    vert_.resize(3 * nt);
    parallelFor(nf, [&](std::size_t f) {
      const std::uint32_t s0 = in_.faceStart[f], n = in_.faceStart[f + 1] - s0;
      if (n != 3 && n != 4) return;
      const auto corners = triangleCorners(n, shape[f] & 1);
      const bool oneHalfDegenerate = n == 4 && ((shape[f] >> 1) & 1) != ((shape[f] >> 2) & 1);
      std::uint32_t good = goodStart_[f], bad = static_cast<std::uint32_t>(numGood_) + degenerateStart[f];
      unsigned inGoodTriangle = 0;  // bit i: face corner i
      for (unsigned k = 0; k < (n == 4 ? 2u : 1u); ++k) {
        const bool degenerate = shape[f] & (2u << k);
        const std::uint32_t t = degenerate ? bad++ : good++;
        Tri& tri = tris_[t];
        tri.face = static_cast<std::int32_t>(f);
        tri.corner = corners[k];
        tri.flags = static_cast<std::uint8_t>((degenerate ? kDegenerate : 0) |
                                              (oneHalfDegenerate ? kQuadOneDegenerate : 0));
        for (int i = 0; i < 3; ++i) {
          slot_[3 * t + i] = s0 + corners[k][i];
          vert_[3 * t + i] = rep_[s0 + corners[k][i]];
          if (!degenerate) inGoodTriangle |= 1u << corners[k][i];
        }
      }
      for (std::uint32_t i = 0; i < n; ++i) {
        if (inGoodTriangle & (1u << i)) continue;
        out_.tangent[s0 + i] = Vec3f{1, 0, 0};
        out_.sign[s0 + i] = -1.0f;
      }
    });
  }

  // The corners of the triangles of a face of @p n corners (a quad split on 0-2 or on 1-3).
  static std::array<std::array<std::uint8_t, 3>, 2> triangleCorners(std::uint32_t n, bool on02) {
    if (n == 3) return {{{0, 1, 2}, {0, 1, 2}}};
    if (on02) return {{{0, 1, 2}, {0, 2, 3}}};
    return {{{0, 1, 3}, {1, 2, 3}}};
  }

  bool isDegenerate(std::uint32_t s0, const std::array<std::uint8_t, 3>& c) const {
    const Vec3f p0 = position(s0 + c[0]), p1 = position(s0 + c[1]), p2 = position(s0 + c[2]);
    return p0 == p1 || p0 == p2 || p1 == p2;
  }

  // The shorter UV diagonal; on a tie the shorter position diagonal; on a tie 0-2.
  bool quadSplitsOn02(std::uint32_t s0) const {
    const float uv02 = lengthSquared(in_.uv[s0 + 2] - in_.uv[s0]);
    const float uv13 = lengthSquared(in_.uv[s0 + 3] - in_.uv[s0 + 1]);
    if (uv02 < uv13) return true;
    if (uv13 < uv02) return false;
    const float p02 = lengthSquared(position(s0 + 2) - position(s0));
    const float p13 = lengthSquared(position(s0 + 3) - position(s0 + 1));
    return !(p13 < p02);
  }

  // Step 5: UV derivatives of each good triangle, and its CornerFrames, computed here once, while
  // the triangle's data is at hand. Triangles go in blocks: the derivatives per triangle, then
  // the four projections per corner (the two edges at the corner, for its angle, dP/ds and dP/dt)
  // four corners at a time.
  void initTriangles() {
    cornerFrame_.resize(3 * numGood_);
    const std::size_t numBlocks = (numGood_ + kBlock - 1) / kBlock;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, numBlocks, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      // Per corner of a block, by component: the edge to the previous corner, the edge to the
      // next one, the triangle's dP/ds and dP/dt, the corner's normal. The projections overwrite
      // their inputs; the first array receives the dot products of the projected edges.
      enum { kPrevious, kNext, kOs, kOt, kNormal, kVectors };
      alignas(16) Staged staged[kVectors];
      for (std::size_t block = r.begin(); block != r.end(); ++block) {
        const std::size_t t0 = block * kBlock, t1 = std::min(numGood_, t0 + kBlock);
        const std::size_t corners = 3 * (t1 - t0);
        for (std::size_t t = t0; t < t1; ++t) {
          const TriFrame d = derivatives(t);
          for (std::uint32_t i = 0; i < 3; ++i) {
            const std::size_t j = 3 * (t - t0) + i;
            const Vec3f corner = position(vert_[3 * t + i]);
            stage(staged[kPrevious], j, position(vert_[3 * t + prev(i)]) - corner);
            stage(staged[kNext], j, position(vert_[3 * t + next(i)]) - corner);
            stage(staged[kOs], j, d.os);
            stage(staged[kOt], j, d.ot);
            stage(staged[kNormal], j, in_.normal[vert_[3 * t + i]]);
          }
        }
        for (std::size_t j = corners; j % 4 != 0; ++j)  // pad the last group of four
          for (auto& vector : staged)
            for (auto& component : vector) component[j] = 0.0f;
        for (std::size_t j = 0; j < corners; j += 4) {
          auto load = [&](int vector) {
            return Vec3x4{Float4::load(&staged[vector][0][j]), Float4::load(&staged[vector][1][j]),
                          Float4::load(&staged[vector][2][j])};
          };
          auto store = [&](int vector, Vec3x4 v) {
            v.x.store(&staged[vector][0][j]);
            v.y.store(&staged[vector][1][j]);
            v.z.store(&staged[vector][2][j]);
          };
          const Vec3x4 n = load(kNormal);
          dot(projectNormalized(load(kPrevious), n), projectNormalized(load(kNext), n)).store(&staged[kPrevious][0][j]);
          store(kOs, projectNormalized(load(kOs), n));
          store(kOt, projectNormalized(load(kOt), n));
        }
        for (std::size_t j = 0; j < corners; ++j) {
          CornerFrame& frame = cornerFrame_[3 * t0 + j];
          frame.angle = safeAcos(staged[kPrevious][0][j]);  // the interior angle at the corner
          frame.os = {staged[kOs][0][j], staged[kOs][1][j], staged[kOs][2][j]};
          frame.ot = {staged[kOt][0][j], staged[kOt][1][j], staged[kOt][2][j]};
        }
      }
    });
  }

  static constexpr std::size_t kBlock = 64;  // triangles per block of initTriangles
  using Staged = float[3][3 * kBlock];       // a vector per corner of a block, by component

  static void stage(Staged& vector, std::size_t j, Vec3f v) {
    vector[0][j] = v.x;
    vector[1][j] = v.y;
    vector[2][j] = v.z;
  }

  // Triangle t's flags (orientation, "group with any") and its derivatives.
  TriFrame derivatives(std::size_t t) {
    Tri& tri = tris_[t];
    tri.flags |= kGroupWithAny;  // until proven healthy
    const std::uint32_t a = vert_[3 * t], b = vert_[3 * t + 1], c = vert_[3 * t + 2];
    const Vec3f v1 = position(a), v2 = position(b), v3 = position(c);
    const Vec2f t1 = in_.uv[a], t2 = in_.uv[b], t3 = in_.uv[c];
    const float t21x = t2.x - t1.x, t21y = t2.y - t1.y;
    const float t31x = t3.x - t1.x, t31y = t3.y - t1.y;
    const Vec3f d1 = v2 - v1, d2 = v3 - v1;
    const float area2 = t21x * t31y - t21y * t31x;
    const Vec3f os = t31y * d1 - t21y * d2;
    const Vec3f ot = -t31x * d1 + t21x * d2;
    if (area2 > 0) tri.flags |= kOrientPreserving;
    TriFrame result{};
    if (!notZero(area2)) return result;
    const float absArea = std::abs(area2);
    const float lenOs = length(os), lenOt = length(ot);
    const float sign = (tri.flags & kOrientPreserving) ? 1.0f : -1.0f;
    if (notZero(lenOs)) result.os = (sign / lenOs) * os;
    if (notZero(lenOt)) result.ot = (sign / lenOt) * ot;
    if (notZero(lenOs / absArea) && notZero(lenOt / absArea))
      tri.flags &= static_cast<std::uint8_t>(~kGroupWithAny);
    return result;
  }

  // Both halves of a healthy quad take the orientation of the half with the larger UV area
  // (or of the first half when the second has no usable derivative).
  void unifyQuadOrientation() {
    if (numGood_ < 2) return;
    parallelFor(numGood_ - 1, [&](std::size_t t) {
      Tri& a = tris_[t];
      Tri& b = tris_[t + 1];
      if (a.face != b.face) return;
      if ((a.flags & kOrientPreserving) == (b.flags & kOrientPreserving)) return;
      const bool chooseFirst =
          (b.flags & kGroupWithAny) ||
          std::abs(uvArea2(in_, vert_[3 * t], vert_[3 * t + 1], vert_[3 * t + 2])) >=
              std::abs(uvArea2(in_, vert_[3 * t + 3], vert_[3 * t + 4], vert_[3 * t + 5]));
      const Tri& from = chooseFirst ? a : b;
      Tri& to = chooseFirst ? b : a;
      to.flags = static_cast<std::uint8_t>((to.flags & ~kOrientPreserving) |
                                           (from.flags & kOrientPreserving));
    });
  }

  // The good triangle corners at welded vertex @p v, ascending.
  std::span<const std::uint32_t> cornersAt(std::size_t v) const {
    return {vertexCorners_.begin() + vertexStart_[v], vertexCorners_.begin() + vertexStart_[v + 1]};
  }

  // Runs body(v, corners at v) for every welded vertex, in parallel.
  template <class Body>
  void forEachVertex(Body body) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in_.numSlots(), kGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v != r.end(); ++v) {
        const auto corners = cornersAt(v);
        if (!corners.empty()) body(static_cast<std::uint32_t>(v), corners);
      }
    });
  }

  // Triangles sharing an edge (by welded vertices) in opposite directions are neighbours. Each
  // edge is paired at its smaller vertex, where the edges are ordered by (larger vertex,
  // triangle); each unpaired edge pairs with the first later unpaired edge running the other way.
  // For the serial group walk, which crosses edges anywhere; the per-vertex groups pair the
  // edges at their vertex themselves (pairEdges).
  void findNeighbors() {
    neighbor_.resize(3 * numGood_);
    neighbor_.fill(kNoTri);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in_.numSlots(), kGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<std::uint64_t> buffer;  // (larger vertex << 32) | edge
      for (std::size_t v = r.begin(); v != r.end(); ++v) {
        const auto corners = cornersAt(v);
        if (corners.size() < 2) continue;
        // The edges at v whose other vertex is larger: each corner's outgoing edge (its own
        // number) and incoming edge (the previous corner's).
        if (buffer.size() < 2 * corners.size()) buffer.resize(2 * corners.size());
        std::size_t count = 0;
        for (const std::uint32_t c : corners) {
          const std::uint32_t to = vert_[next(c)], from = vert_[prev(c)];
          if (to > v) buffer[count++] = (std::uint64_t{to} << 32) | c;
          if (from > v) buffer[count++] = (std::uint64_t{from} << 32) | prev(c);
        }
        const std::span<std::uint64_t> edges(buffer.data(), count);
        insertionSortStable(edges.begin(), edges.end(), std::less<>{});
        for (auto a = edges.begin(); a != edges.end(); ++a) {
          const auto ea = static_cast<std::uint32_t>(*a);
          if (neighbor_[ea] != kNoTri) continue;
          for (auto b = a + 1; b != edges.end() && (*b >> 32) == (*a >> 32); ++b) {
            const auto eb = static_cast<std::uint32_t>(*b);
            if (vert_[eb] == vert_[next(ea)] && vert_[next(eb)] == vert_[ea] && neighbor_[eb] == kNoTri) {
              neighbor_[ea] = static_cast<std::int32_t>(eb / 3);
              neighbor_[eb] = static_cast<std::int32_t>(ea / 3);
              break;
            }
          }
        }
      }
    });
  }

  // Steps 6 to 8 when no triangle is "group with any": a group is a connected set of
  // same-orientation triangles around a vertex (connected across the two edges at the vertex),
  // which does not depend on the order it is found in, so each vertex finds its groups on its
  // own, in parallel, evaluates them and writes the frames of its slots. The neighbours across
  // the edges at the vertex are paired here too (see pairEdges).
  void buildAndEvaluateGroupsPerVertex() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in_.numSlots(), kGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
      Scratch sc;
      // Per corner at the vertex: the corner (index at the vertex) across its outgoing and its
      // incoming edge, or -1; its group, or -1; its group's tangent. The depth-first stack (each
      // corner is pushed once). They only grow.
      std::vector<std::array<std::int32_t, 2>> across;
      std::vector<std::int32_t> component;
      std::vector<Vec3f> frames;
      std::vector<std::uint32_t> stack, members, memberIndex;
      std::vector<Edge> edges;
      for (std::size_t v = r.begin(); v != r.end(); ++v) {
        const auto corners = cornersAt(v);
        const std::size_t k = corners.size();
        if (k == 0) continue;
        if (component.size() < k) {
          across.resize(k);
          component.resize(k);
          frames.resize(k);
          stack.resize(k);
          edges.resize(2 * k);
        }
        pairEdges(corners, edges.data(), across.data());
        std::fill_n(component.begin(), k, -1);
        std::int32_t groups = 0;
        for (std::size_t first = 0; first < k; ++first) {
          if (component[first] >= 0) continue;
          const bool orient = tris_[corners[first] / 3].flags & kOrientPreserving;
          component[first] = groups;
          std::size_t size = 0;  // of the stack
          stack[size++] = static_cast<std::uint32_t>(first);
          while (size > 0) {
            for (const std::int32_t j : across[stack[--size]]) {
              if (j < 0 || component[static_cast<std::size_t>(j)] >= 0) continue;
              if (static_cast<bool>(tris_[corners[static_cast<std::size_t>(j)] / 3].flags & kOrientPreserving) != orient) continue;
              component[static_cast<std::size_t>(j)] = groups;
              stack[size++] = static_cast<std::uint32_t>(j);
            }
          }
          ++groups;
        }
        if (groups == 1) {
          evaluateGroup(corners, sc, [&](std::uint32_t j, Vec3f tangent) { frames[j] = tangent; });
        } else {
          for (std::int32_t g = 0; g < groups; ++g) {
            members.clear();
            memberIndex.clear();
            for (std::size_t j = 0; j < k; ++j) {
              if (component[j] != g) continue;
              members.push_back(corners[j]);
              memberIndex.push_back(static_cast<std::uint32_t>(j));
            }
            evaluateGroup(members, sc, [&](std::uint32_t j, Vec3f tangent) { frames[memberIndex[j]] = tangent; });
          }
        }
        writeSlots(corners, [&](std::size_t j, Vec3f& tangent) {
          tangent = frames[j];
          return true;
        });
      }
    });
  }

  // An edge at a vertex, for pairEdges: the other vertex and the edge's number (the sort key),
  // and which corner at the vertex it belongs to, as its outgoing or incoming edge.
  struct Edge {
    std::uint64_t key;   // (other vertex << 32) | edge
    std::uint32_t corner;  // index at the vertex
    std::uint32_t side;    // 0: the corner's outgoing edge, 1: its incoming edge
  };

  // The neighbour pairing of findNeighbors for all edges at vertex @p v at once: the edges
  // between v and another vertex w, in edge order, are the same list seen from v or from w, so
  // pairing them here gives the pairs findNeighbors gives. For the corners @p corners at one
  // vertex, across[j] = the corners (indices in @p corners) across corner j's outgoing and
  // incoming edges, or -1. @p edges has room for two edges per corner.
  void pairEdges(std::span<const std::uint32_t> corners, Edge* edges, std::array<std::int32_t, 2>* across) const {
    const std::size_t k = corners.size();
    for (std::size_t j = 0; j < k; ++j) {
      const std::uint32_t c = corners[j];
      edges[2 * j] = {(std::uint64_t{vert_[next(c)]} << 32) | c, static_cast<std::uint32_t>(j), 0};
      edges[2 * j + 1] = {(std::uint64_t{vert_[prev(c)]} << 32) | prev(c), static_cast<std::uint32_t>(j), 1};
      across[j] = {-1, -1};
    }
    insertionSortStable(edges, edges + 2 * k, [](const Edge& a, const Edge& b) { return a.key < b.key; });
    // Each unpaired edge pairs with the first later unpaired edge to the same vertex running the
    // other way (an outgoing edge of one corner with an incoming edge of another).
    auto paired = [&](const Edge& e) { return across[e.corner][e.side] >= 0; };
    for (std::size_t a = 0; a < 2 * k; ++a) {
      if (paired(edges[a])) continue;
      for (std::size_t b = a + 1; b < 2 * k && (edges[b].key >> 32) == (edges[a].key >> 32); ++b) {
        if (edges[b].side != edges[a].side && !paired(edges[b])) {
          across[edges[a].corner][edges[a].side] = static_cast<std::int32_t>(edges[b].corner);
          across[edges[b].corner][edges[b].side] = static_cast<std::int32_t>(edges[a].corner);
          break;
        }
      }
    }
  }

  // Steps 6 to 8 with "group with any" triangles: groups are found by a depth-first walk across
  // the two edges at the vertex (the left edge's side first), vertices in triangle corner order.
  // Serial: the first group to reach a "group with any" triangle decides its orientation, so the
  // order is part of the result. The groups are then evaluated, and slots written, in parallel.
  void buildAndEvaluateGroupsSerially() {
    std::vector<std::int32_t> group(3 * numGood_, -1);  // per triangle corner
    std::vector<std::uint32_t> groupStart{0}, groupCorners;  // group g's corners: [groupStart[g], groupStart[g+1])
    groupCorners.reserve(3 * numGood_);
    std::vector<std::int32_t> stack;
    auto pushNeighbors = [&](std::uint32_t c) {
      const std::int32_t left = neighbor_[c], right = neighbor_[prev(c)];
      if (right >= 0) stack.push_back(right);  // popped after the whole left side
      if (left >= 0) stack.push_back(left);
    };
    for (std::uint32_t c0 = 0; c0 < 3 * numGood_; ++c0) {
      if ((tris_[c0 / 3].flags & kGroupWithAny) || group[c0] >= 0) continue;
      const auto g = static_cast<std::int32_t>(groupStart.size() - 1);
      const std::uint32_t vertex = vert_[c0];
      const bool orient = tris_[c0 / 3].flags & kOrientPreserving;
      group[c0] = g;
      groupCorners.push_back(c0);
      stack.clear();
      pushNeighbors(c0);
      while (!stack.empty()) {
        const auto m = static_cast<std::uint32_t>(stack.back());
        stack.pop_back();
        Tri& other = tris_[m];
        std::uint32_t c = 3 * m;  // m's corner at the vertex
        while (vert_[c] != vertex) ++c;
        if (group[c] >= 0) continue;  // in this group already, or in another one
        if ((other.flags & kGroupWithAny) && group[3 * m] < 0 && group[3 * m + 1] < 0 && group[3 * m + 2] < 0) {
          other.flags = static_cast<std::uint8_t>((other.flags & ~kOrientPreserving) |
                                                  (orient ? kOrientPreserving : 0));
        }
        if (static_cast<bool>(other.flags & kOrientPreserving) != orient) continue;
        group[c] = g;
        groupCorners.push_back(c);
        pushNeighbors(c);
      }
      groupStart.push_back(static_cast<std::uint32_t>(groupCorners.size()));
    }
    // Corners no group reached have no frame of their own.
    ParallelArray<Vec3f> cornerSpace(3 * numGood_);  // per triangle corner in a group: the group's tangent
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groupStart.size() - 1, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
      Scratch sc;
      std::vector<std::uint32_t> members;
      for (std::size_t g = r.begin(); g != r.end(); ++g) {
        members.assign(groupCorners.begin() + groupStart[g], groupCorners.begin() + groupStart[g + 1]);
        insertionSortStable(members.begin(), members.end(), std::less<>{});  // triangle order
        evaluateGroup(members, sc, [&](std::uint32_t j, Vec3f tangent) { cornerSpace[members[j]] = tangent; });
      }
    });
    forEachVertex([&](std::uint32_t, std::span<const std::uint32_t> corners) {
      writeSlots(corners, [&](std::size_t j, Vec3f& tangent) {
        if (group[corners[j]] < 0) return false;
        tangent = cornerSpace[corners[j]];
        return true;
      });
    });
  }

  // Step 8: the frames of the slots of the triangle corners @p corners at one vertex
  // (ascending); frameOf(j, tangent) gives corner j's frame, or false when no group has it.
  // A slot shared by both halves of a quad has two corners here, adjacent (the halves are
  // consecutive triangles, each with one corner at the vertex): its frame averages theirs, in
  // triangle order. Its orientation is that of each triangle of the group (and the halves agree).
  template <class FrameOf>
  void writeSlots(std::span<const std::uint32_t> corners, FrameOf frameOf) const {
    std::uint32_t previousSlot = kNone;
    int written = 0;  // frames written to the current slot
    for (std::size_t j = 0; j < corners.size(); ++j) {
      const std::uint32_t slot = slot_[corners[j]];
      const bool newSlot = slot != previousSlot;
      if (newSlot) {
        previousSlot = slot;
        written = 0;
      }
      Vec3f tangent;
      if (!frameOf(j, tangent)) {
        if (newSlot) {  // the algorithm's default frame, unless the other half writes one
          out_.tangent[slot] = Vec3f{1, 0, 0};
          out_.sign[slot] = -1.0f;
        }
        continue;
      }
      out_.tangent[slot] = written++ == 1 ? average(out_.tangent[slot], tangent) : tangent;
      out_.sign[slot] = (tris_[corners[j] / 3].flags & kOrientPreserving) ? 1.0f : -1.0f;
    }
  }

  // Per-thread buffers of evaluateGroup, indexed by a triangle's rank in its group.
  // They only grow, so that evaluating a group allocates nothing.
  struct Scratch {
    std::vector<Member> members;       // what the sub-group test and the average read of each
    std::vector<std::uint64_t> masks;  // per triangle: the bitset of triangles in its sub-group
    std::vector<std::uint32_t> uniqueOwner;  // per distinct sub-group: a triangle that has it
    std::vector<Vec3f> uniqueSpace;          // per distinct sub-group: its tangent
  };

  // Step 7: the tangent of each triangle corner of the group made of @p corners (ascending, all
  // at one vertex), passed to output(j, tangent) for corners[j]. Each triangle of the group
  // gathers a sub-group: the triangles whose projected derivatives do not point exactly opposite
  // to its own (the algorithm's default angular threshold of 180 degrees), plus those of its own
  // face and any "group with any" triangle. Each distinct sub-group gets the angle-weighted
  // average of its members' tangents, summed in ascending triangle order. The test is
  // symmetric, so each pair is tested once.
  template <class Output>
  void evaluateGroup(std::span<const std::uint32_t> corners, Scratch& sc, Output output) const {
    constexpr float kThresholdCos = -1.0f;
    const auto k = static_cast<std::uint32_t>(corners.size());
    // The common case: every pair is linked, so every sub-group is the whole group.
    if (k == 1 || allWithinCone(corners)) {
      Vec3f os{0, 0, 0};
      for (const std::uint32_t c : corners)
        if (!(tris_[c / 3].flags & kGroupWithAny)) os += cornerFrame_[c].angle * cornerFrame_[c].os;
      const Vec3f tangent = normalizeIfNotZero(os);
      for (std::uint32_t j = 0; j < k; ++j) output(j, tangent);
      return;
    }

    if (sc.members.size() < k) sc.members.resize(k);
    Member* m = sc.members.data();
    for (std::uint32_t j = 0; j < k; ++j) {
      const CornerFrame& frame = cornerFrame_[corners[j]];
      const Tri& tri = tris_[corners[j] / 3];
      m[j] = {frame.os, frame.ot, frame.angle, tri.face, (tri.flags & kGroupWithAny) != 0};
    }
    auto linked = [&](std::uint32_t j, std::uint32_t l) {
      return m[j].any || m[l].any || m[j].face == m[l].face ||
             (dot(m[j].os, m[l].os) > kThresholdCos && dot(m[j].ot, m[l].ot) > kThresholdCos);
    };
    bool allLinked = true;
    for (std::uint32_t j = 0; j < k && allLinked; ++j)
      for (std::uint32_t l = j + 1; l < k && allLinked; ++l) allLinked = linked(j, l);
    if (allLinked) {
      const Vec3f tangent = subgroupTangent(m, k, [](std::uint32_t) { return true; });
      for (std::uint32_t j = 0; j < k; ++j) output(j, tangent);
      return;
    }

    const std::uint32_t words = (k + 63) / 64;
    if (sc.masks.size() < std::size_t{k} * words) sc.masks.resize(std::size_t{k} * words);
    std::uint64_t* masks = sc.masks.data();
    std::fill_n(masks, std::size_t{k} * words, 0);
    auto set = [&](std::uint32_t row, std::uint32_t col) { masks[row * words + col / 64] |= std::uint64_t{1} << (col % 64); };
    for (std::uint32_t j = 0; j < k; ++j) {
      set(j, j);
      for (std::uint32_t l = j + 1; l < k; ++l) {
        if (linked(j, l)) {
          set(j, l);
          set(l, j);
        }
      }
    }
    sc.uniqueOwner.clear();
    sc.uniqueSpace.clear();
    for (std::uint32_t j = 0; j < k; ++j) {
      const std::uint64_t* mask = masks + j * words;
      std::size_t u = 0;
      while (u < sc.uniqueOwner.size() && !std::equal(mask, mask + words, masks + sc.uniqueOwner[u] * words)) ++u;
      if (u == sc.uniqueOwner.size()) {
        sc.uniqueOwner.push_back(j);
        sc.uniqueSpace.push_back(subgroupTangent(m, k, [&](std::uint32_t l) { return (mask[l / 64] >> (l % 64)) & 1; }));
      }
      output(j, sc.uniqueSpace[u]);
    }
  }

  // A cheap sufficient condition for every pair of the group being linked: every projected dP/ds
  // lies within about 87 degrees of the first triangle's, and so does every dP/dt. Any two are
  // then less than 174 degrees apart, so their dot products (cos < -0.99 at worst, before a
  // rounding error of a few ulps) are above the threshold of -1, and the pairwise test would
  // say "linked" for every pair. When the condition fails, the pairwise test decides.
  bool allWithinCone(std::span<const std::uint32_t> corners) const {
    constexpr float kMinCos = 0.05f;  // cos(87.1 degrees)
    const Vec3f os0 = cornerFrame_[corners[0]].os, ot0 = cornerFrame_[corners[0]].ot;
    for (const std::uint32_t c : corners.subspan(1)) {
      if (!(dot(os0, cornerFrame_[c].os) > kMinCos && dot(ot0, cornerFrame_[c].ot) > kMinCos)) return false;
    }
    return true;
  }


  // The angle-weighted average of the tangents of the members @p in the sub-group.
  template <class InSubgroup>
  static Vec3f subgroupTangent(const Member* m, std::uint32_t k, InSubgroup in) {
    Vec3f os{0, 0, 0};
    for (std::uint32_t j = 0; j < k; ++j)
      if (!m[j].any && in(j)) os += m[j].angle * m[j].os;
    return normalizeIfNotZero(os);
  }

  // The degenerate epilogue. Degenerate triangles copy the frame of the first good triangle
  // corner with the same welded vertex; the corner a good half of a quad does not use (its other
  // half being degenerate) takes the frame of the corner at the same position.
  void copyToDegenerate() {
    if (numGood_ == tris_.size()) return;  // no degenerate triangles
    for (std::size_t t = numGood_; t < tris_.size(); ++t) {
      if (tris_[t].flags & kQuadOneDegenerate) continue;
      for (std::uint32_t i = 0; i < 3; ++i) {
        const auto corners = cornersAt(vert_[3 * t + i]);
        if (corners.empty()) continue;
        out_.tangent[slot_[3 * t + i]] = out_.tangent[slot_[corners[0]]];
        out_.sign[slot_[3 * t + i]] = out_.sign[slot_[corners[0]]];
      }
    }
    // Each such quad reads and writes its own slots only.
    parallelFor(numGood_, [&](std::size_t t) {
      const Tri& tri = tris_[t];
      if (!(tri.flags & kQuadOneDegenerate)) return;
      const unsigned used = (1u << tri.corner[0]) | (1u << tri.corner[1]) | (1u << tri.corner[2]);
      int missing = 0;
      while (missing < 4 && (used & (1u << missing))) ++missing;
      if (missing == 4) return;
      const std::uint32_t s0 = in_.faceStart[static_cast<std::size_t>(tri.face)];
      const Vec3f target = position(s0 + missing);
      for (int i = 0; i < 3; ++i) {
        if (position(s0 + tri.corner[i]) == target) {
          out_.tangent[s0 + missing] = out_.tangent[s0 + tri.corner[i]];
          out_.sign[s0 + missing] = out_.sign[s0 + tri.corner[i]];
          break;
        }
      }
    });
  }

  const Input& in_;
  const Output& out_;
  ParallelArray<std::uint32_t> rep_;  // welded vertex (smallest equal slot) of each slot

  std::vector<std::uint32_t> goodStart_;  // #faces+1: face f's good triangles in work order
  ParallelArray<Tri> tris_;               // work order
  ParallelArray<std::uint32_t> slot_;     // per triangle corner: its slot
  ParallelArray<std::uint32_t> vert_;     // per triangle corner: its welded vertex
  std::size_t numGood_ = 0;

  ParallelArray<CornerFrame> cornerFrame_;      // per good triangle corner
  ParallelArray<std::uint32_t> vertexStart_;    // #slots+1: welded vertex v's corners in vertexCorners_
  ParallelArray<std::uint32_t> vertexCorners_;  // good triangle corners by welded vertex, ascending
  ParallelArray<std::int32_t> neighbor_;        // per good triangle edge: the triangle across, or -1 (serial walk only)
};

}  // namespace

void generate(const Input& input, const Output& output) { Engine(input, output).run(); }

}  // namespace sgbake::mikk
