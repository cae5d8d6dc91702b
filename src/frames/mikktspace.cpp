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
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

#include <sys/mman.h>

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

// Large work arrays: allocated on 2 MiB boundaries with transparent huge pages requested, and
// constructed by all threads at once. The first touch of fresh memory (a page fault and zeroing
// per 4 KiB page) would otherwise be a large part of this algorithm's cost, paid on one thread.
constexpr std::size_t kHugePage = std::size_t{2} << 20;

void* allocateLarge(std::size_t bytes) {
  if (bytes < kHugePage) return ::operator new(bytes);
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (p == nullptr) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  madvise(p, rounded, MADV_HUGEPAGE);  // a hint: failure only costs speed
#endif
  return p;
}

void freeLarge(void* p, std::size_t bytes) {
  if (bytes < kHugePage) {
    ::operator delete(p);
  } else {
    std::free(p);
  }
}

template <class T>
class ParallelArray {
  static_assert(std::is_trivially_destructible_v<T>);

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
    parallelFor(n, [&](std::size_t i) { ::new (static_cast<void*>(data_ + i)) T(); });
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
  const Vec3f p = in.position[s], n = in.normal[s];
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

  // Partition items by the top bits of their hash (a stable counting sort, so each bucket lists
  // its items in ascending order), then weld each bucket with its own small hash table over a
  // copy of its keys, so that a bucket touches only its own memory.
  constexpr int kBucketBits = 8;
  constexpr std::size_t kBuckets = std::size_t{1} << kBucketBits;
  auto bucketOf = [&](std::size_t s) { return hash[s] >> (64 - kBucketBits); };
  std::vector<std::uint32_t> bucketStart(kBuckets + 1, 0);
  for (std::size_t s = 0; s < n; ++s) ++bucketStart[bucketOf(s) + 1];
  for (std::size_t b = 0; b < kBuckets; ++b) bucketStart[b + 1] += bucketStart[b];
  ParallelArray<std::uint32_t> order(n);
  {
    std::vector<std::uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
    for (std::size_t s = 0; s < n; ++s) order[fill[bucketOf(s)]++] = static_cast<std::uint32_t>(s);
  }

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

// Welding with vertex ids: positions are hashed once per used vertex, and each slot is compared
// (normal and UV) only with the slots of vertices at its position, a handful on most meshes.
ParallelArray<std::uint32_t> weldByVertex(const Input& in) {
  const std::size_t n = in.position.size();
  assert(in.vertex.size() == n);
  // The used vertices in ascending order, each with one of its slots (all share its position).
  std::vector<std::uint32_t> slotOf(in.numVertices, kNone);
  for (std::size_t s = 0; s < n; ++s) slotOf[in.vertex[s]] = static_cast<std::uint32_t>(s);
  std::vector<std::uint32_t> used;     // used vertex index → a slot of it
  std::vector<std::uint32_t> usedIndex(in.numVertices, kNone);  // vertex → used vertex index
  used.reserve(in.numVertices);
  for (std::uint32_t v = 0; v < in.numVertices; ++v) {
    if (slotOf[v] == kNone) continue;
    usedIndex[v] = static_cast<std::uint32_t>(used.size());
    used.push_back(slotOf[v]);
  }
  // Position classes: the smallest used vertex index at the same position.
  const ParallelArray<std::uint32_t> positionClass = weldByHash(used.size(), [&](std::size_t u) {
    const Vec3f p = in.position[used[u]];
    return keyOf<3>({p.x, p.y, p.z});
  });
  ParallelArray<std::uint32_t> classOf(n);
  parallelFor(n, [&](std::size_t s) { classOf[s] = positionClass[usedIndex[in.vertex[s]]]; });

  // Slots by position class (a stable counting sort: each class lists its slots ascending).
  std::vector<std::uint32_t> start(used.size() + 1, 0);
  for (std::size_t s = 0; s < n; ++s) ++start[classOf[s] + 1];
  for (std::size_t c = 0; c < used.size(); ++c) start[c + 1] += start[c];
  ParallelArray<std::uint32_t> order(n);
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t s = 0; s < n; ++s) order[fill[classOf[s]]++] = static_cast<std::uint32_t>(s);
  }

  // Within a class, each slot welds to the first earlier slot with the same normal and UV.
  ParallelArray<std::uint32_t> rep(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    constexpr std::uint32_t kLinearScan = 32;  // longer classes sort their keys instead
    std::vector<std::pair<Key<5>, std::uint32_t>> sorted;
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const std::uint32_t begin = start[c], size = start[c + 1] - begin;
      const std::uint32_t* slots = order.begin() + begin;
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
      for (std::uint32_t k = 0; k < size; ++k) sorted.emplace_back(attributeKey(in, slots[k]), slots[k]);
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
  const bool shared = std::size_t{2} * in.numVertices <= in.position.size();
  if (!in.vertex.empty() && shared) return weldByVertex(in);
  return weldByHash(in.position.size(), [&](std::size_t s) { return weldKey(in, s); });
}

// ---------------------------------------------------------------------------------------------
// Per-triangle state.

struct Tri {
  Vec3f os{}, ot{};          // unit dP/ds, dP/dt (sign-corrected), or zero
  std::int32_t face = 0;     // input face
  std::array<std::int32_t, 3> neighbor{kNoTri, kNoTri, kNoTri};  // across edge (i, i+1)
  std::array<std::int32_t, 3> group{-1, -1, -1};                 // group of corner i
  std::array<float, 3> angle{};   // interior angle at corner i, in the plane of its normal
  std::array<std::uint8_t, 3> corner{};                         // corner i = face corner
  std::uint8_t flags = 0;
};

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
  std::uint8_t corner;   // which corner of the triangle the vertex is
};

Vec3f projectNormalized(Vec3f v, Vec3f n) { return normalizeIfNotZero(v - dot(n, v) * n); }

float uvArea2(const Input& in, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const Vec2f t1 = in.uv[a], t2 = in.uv[b], t3 = in.uv[c];
  const float t21x = t2.x - t1.x, t21y = t2.y - t1.y;
  const float t31x = t3.x - t1.x, t31y = t3.y - t1.y;
  return t21x * t31y - t21y * t31x;
}

class Engine {
 public:
  Engine(const Input& in, Output& out) : in_(in), out_(out) {}

  void run() {
    rep_ = weld(in_);
    splitFaces();
    initTriangles();
    unifyQuadOrientation();
    findNeighbors();
    buildGroups();
    evaluateGroups();
    resolve();
  }

 private:
  // Steps 3 and 4: split faces into triangles, written straight into work order (good triangles
  // in input order, then degenerate ones in input order).
  void splitFaces() {
    const std::size_t nf = in_.faceStart.size() - 1;
    // Per face: bit 0 = quad split on 0-2, bits 1/2 = first/second triangle degenerate,
    // bits 3/4 = first/second triangle exists.
    std::vector<std::uint8_t> shape(nf);
    parallelFor(nf, [&](std::size_t f) {
      const std::uint32_t s0 = in_.faceStart[f], n = in_.faceStart[f + 1] - s0;
      if (n != 3 && n != 4) return;
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
        }
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
    const Vec3f p0 = in_.position[s0 + c[0]], p1 = in_.position[s0 + c[1]], p2 = in_.position[s0 + c[2]];
    return p0 == p1 || p0 == p2 || p1 == p2;
  }

  // The shorter UV diagonal; on a tie the shorter position diagonal; on a tie 0-2.
  bool quadSplitsOn02(std::uint32_t s0) const {
    const float uv02 = lengthSquared(in_.uv[s0 + 2] - in_.uv[s0]);
    const float uv13 = lengthSquared(in_.uv[s0 + 3] - in_.uv[s0 + 1]);
    if (uv02 < uv13) return true;
    if (uv13 < uv02) return false;
    const float p02 = lengthSquared(in_.position[s0 + 2] - in_.position[s0]);
    const float p13 = lengthSquared(in_.position[s0 + 3] - in_.position[s0 + 1]);
    return !(p13 < p02);
  }

  // Step 5: UV derivatives of each good triangle.
  void initTriangles() {
    parallelFor(numGood_, [&](std::size_t t) {
      Tri& tri = tris_[t];
      tri.flags |= kGroupWithAny;  // until proven healthy
      const std::uint32_t a = vert_[3 * t], b = vert_[3 * t + 1], c = vert_[3 * t + 2];
      const Vec3f v1 = in_.position[a], v2 = in_.position[b], v3 = in_.position[c];
      const Vec2f t1 = in_.uv[a], t2 = in_.uv[b], t3 = in_.uv[c];
      const float t21x = t2.x - t1.x, t21y = t2.y - t1.y;
      const float t31x = t3.x - t1.x, t31y = t3.y - t1.y;
      const Vec3f d1 = v2 - v1, d2 = v3 - v1;
      for (int i = 0; i < 3; ++i) tri.angle[i] = cornerAngle(t, i);
      const float area2 = t21x * t31y - t21y * t31x;
      const Vec3f os = t31y * d1 - t21y * d2;
      const Vec3f ot = -t31x * d1 + t21x * d2;
      if (area2 > 0) tri.flags |= kOrientPreserving;
      if (!notZero(area2)) return;
      const float absArea = std::abs(area2);
      const float lenOs = length(os), lenOt = length(ot);
      const float sign = (tri.flags & kOrientPreserving) ? 1.0f : -1.0f;
      if (notZero(lenOs)) tri.os = (sign / lenOs) * os;
      if (notZero(lenOt)) tri.ot = (sign / lenOt) * ot;
      if (notZero(lenOs / absArea) && notZero(lenOt / absArea))
        tri.flags &= static_cast<std::uint8_t>(~kGroupWithAny);
    });
  }

  // The interior angle of triangle @p t at corner @p i, measured in the plane orthogonal to the
  // corner's normal.
  float cornerAngle(std::size_t t, int i) const {
    const Vec3f n = in_.normal[vert_[3 * t + i]];
    const Vec3f p0 = in_.position[vert_[3 * t + (i > 0 ? i - 1 : 2)]];
    const Vec3f p1 = in_.position[vert_[3 * t + i]];
    const Vec3f p2 = in_.position[vert_[3 * t + (i < 2 ? i + 1 : 0)]];
    const Vec3f e1 = projectNormalized(p0 - p1, n), e2 = projectNormalized(p2 - p1, n);
    return safeAcos(dot(e1, e2));
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

  // Triangles sharing an edge (by welded vertices) in opposite directions are neighbours. Edges
  // are bucketed by their smaller vertex and, inside a bucket, ordered by (larger vertex,
  // triangle); each unpaired edge pairs with the first later unpaired edge running the other way.
  void findNeighbors() {
    const std::size_t ne = 3 * numGood_;
    const std::size_t nv = in_.position.size();
    auto edgeFrom = [&](std::size_t e) { return vert_[e]; };
    auto edgeTo = [&](std::size_t e) { return vert_[e % 3 == 2 ? e - 2 : e + 1]; };
    // Per edge: its smaller vertex, and (larger vertex, edge) packed so that sorting the packed
    // values orders a bucket by larger vertex, then triangle.
    ParallelArray<std::uint32_t> smaller(ne);
    ParallelArray<std::uint64_t> packed(ne);
    parallelFor(ne, [&](std::size_t e) {
      const std::uint32_t a = edgeFrom(e), b = edgeTo(e);
      smaller[e] = std::min(a, b);
      packed[e] = (std::uint64_t{std::max(a, b)} << 32) | e;
    });
    std::vector<std::uint32_t> start(nv + 1, 0);
    for (std::size_t e = 0; e < ne; ++e) ++start[smaller[e] + 1];
    for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    ParallelArray<std::uint64_t> edges(ne);
    {
      std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t e = 0; e < ne; ++e) edges[fill[smaller[e]]++] = packed[e];
    }
    parallelFor(nv, [&](std::size_t v) {
      const auto begin = edges.begin() + start[v], end = edges.begin() + start[v + 1];
      if (end - begin < 2) return;
      insertionSortStable(begin, end, std::less<>{});
      for (auto a = begin; a != end; ++a) {
        const auto ea = static_cast<std::uint32_t>(*a);
        if (tris_[ea / 3].neighbor[ea % 3] != kNoTri) continue;
        for (auto b = a + 1; b != end && (*b >> 32) == (*a >> 32); ++b) {
          const auto eb = static_cast<std::uint32_t>(*b);
          if (edgeFrom(eb) == edgeTo(ea) && edgeTo(eb) == edgeFrom(ea) &&
              tris_[eb / 3].neighbor[eb % 3] == kNoTri) {
            tris_[ea / 3].neighbor[ea % 3] = static_cast<std::int32_t>(eb / 3);
            tris_[eb / 3].neighbor[eb % 3] = static_cast<std::int32_t>(ea / 3);
            break;
          }
        }
      }
    });
  }

  int cornerOf(std::size_t t, std::uint32_t vertex) const {
    for (int i = 0; i < 3; ++i)
      if (vert_[3 * t + i] == vertex) return i;
    return -1;
  }

  // Step 6: groups of same-orientation triangles around each vertex, found by a depth-first walk
  // across the two edges at the vertex (the left edge's side first). Serial: the first group to
  // reach a "group with any" triangle decides its orientation, so the order is part of the result.
  void buildGroups() {
    groupStart_.assign(1, 0);
    groupFaces_.clear();
    groupFaces_.reserve(3 * numGood_);
    std::vector<std::int32_t> stack;
    for (std::size_t t = 0; t < numGood_; ++t) {
      for (int i = 0; i < 3; ++i) {
        Tri& tri = tris_[t];
        if ((tri.flags & kGroupWithAny) || tri.group[i] >= 0) continue;
        const auto g = static_cast<std::int32_t>(groupVertex_.size());
        const std::uint32_t vertex = vert_[3 * t + i];
        const bool orient = tri.flags & kOrientPreserving;
        groupVertex_.push_back(vertex);
        groupOrient_.push_back(orient);
        tri.group[i] = g;
        groupFaces_.push_back(static_cast<std::uint32_t>(t));
        stack.clear();
        pushNeighbors(tri, i, stack);
        while (!stack.empty()) {
          const std::int32_t m = stack.back();
          stack.pop_back();
          Tri& other = tris_[m];
          const int k = cornerOf(static_cast<std::size_t>(m), vertex);
          assert(k >= 0);
          if (other.group[k] >= 0) continue;  // in this group already, or in another one
          if ((other.flags & kGroupWithAny) && other.group[0] < 0 && other.group[1] < 0 &&
              other.group[2] < 0) {
            other.flags = static_cast<std::uint8_t>((other.flags & ~kOrientPreserving) |
                                                    (orient ? kOrientPreserving : 0));
          }
          if (static_cast<bool>(other.flags & kOrientPreserving) != orient) continue;
          other.group[k] = g;
          groupFaces_.push_back(static_cast<std::uint32_t>(m));
          pushNeighbors(other, k, stack);
        }
        groupStart_.push_back(static_cast<std::uint32_t>(groupFaces_.size()));
      }
    }
  }

  static void pushNeighbors(const Tri& tri, int corner, std::vector<std::int32_t>& stack) {
    const std::int32_t left = tri.neighbor[corner];
    const std::int32_t right = tri.neighbor[corner > 0 ? corner - 1 : 2];
    if (right >= 0) stack.push_back(right);  // popped after the whole left side
    if (left >= 0) stack.push_back(left);
  }

  // Per-thread buffers of evaluateGroup, indexed by a triangle's rank in its group's sorted list.
  // They only grow, so that evaluating a group allocates nothing.
  struct Scratch {
    std::vector<std::uint32_t> faces;  // the group's triangles, ascending
    std::vector<Member> members;       // what the sub-group test and the average read of each
    std::vector<std::uint64_t> masks;  // per triangle: the bitset of triangles in its sub-group
    std::vector<std::uint32_t> uniqueOwner;  // per distinct sub-group: a triangle that has it
    std::vector<Vec3f> uniqueSpace;          // per distinct sub-group: its tangent
  };

  // Step 7: a frame per (group, triangle corner).
  void evaluateGroups() {
    cornerSpace_.resize(3 * numGood_);
    const std::size_t ng = groupVertex_.size();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ng, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Scratch scratch;
                        for (std::size_t g = r.begin(); g != r.end(); ++g) evaluateGroup(g, scratch);
                      });
  }

  // Each triangle of the group gathers a sub-group: the triangles whose projected derivatives do
  // not point exactly opposite to its own (the algorithm's default angular threshold of 180
  // degrees), plus those of its own face and any "group with any" triangle. Each distinct
  // sub-group gets the angle-weighted average of its members' tangents, summed in ascending
  // triangle order. The test is symmetric, so each pair is tested once.
  void evaluateGroup(std::size_t g, Scratch& sc) {
    constexpr float kThresholdCos = -1.0f;
    const std::uint32_t vertex = groupVertex_[g];
    const Vec3f n = in_.normal[vertex];
    const std::uint32_t begin = groupStart_[g], k = groupStart_[g + 1] - begin;
    if (sc.faces.size() < k) {
      sc.faces.resize(k);
      sc.members.resize(k);
    }
    std::copy_n(groupFaces_.begin() + begin, k, sc.faces.begin());
    insertionSortStable(sc.faces.begin(), sc.faces.begin() + k, std::less<>{});
    Member* m = sc.members.data();
    for (std::uint32_t j = 0; j < k; ++j) {
      const Tri& tri = tris_[sc.faces[j]];
      const int corner = groupCorner(sc.faces[j], g);
      m[j].os = projectNormalized(tri.os, n);
      m[j].angle = tri.angle[corner];
      m[j].face = tri.face;
      m[j].any = (tri.flags & kGroupWithAny) != 0;
      m[j].corner = static_cast<std::uint8_t>(corner);
    }
    auto output = [&](std::uint32_t j, Vec3f tangent) { cornerSpace_[3 * sc.faces[j] + m[j].corner] = tangent; };
    if (k == 1) {  // a corner welded to no other: its own triangle's frame
      output(0, subgroupTangent(m, k, [](std::uint32_t) { return true; }));
      return;
    }
    for (std::uint32_t j = 0; j < k; ++j) m[j].ot = projectNormalized(tris_[sc.faces[j]].ot, n);
    auto linked = [&](std::uint32_t j, std::uint32_t l) {
      return m[j].any || m[l].any || m[j].face == m[l].face ||
             (dot(m[j].os, m[l].os) > kThresholdCos && dot(m[j].ot, m[l].ot) > kThresholdCos);
    };

    // The common case: every pair is linked, so every sub-group is the whole group.
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

  // The angle-weighted average of the tangents of the members @p in the sub-group.
  template <class InSubgroup>
  static Vec3f subgroupTangent(const Member* m, std::uint32_t k, InSubgroup in) {
    Vec3f os{0, 0, 0};
    for (std::uint32_t j = 0; j < k; ++j)
      if (!m[j].any && in(j)) os += m[j].angle * m[j].os;
    return normalizeIfNotZero(os);
  }

  // Which corner of triangle @p f belongs to group @p g.
  int groupCorner(std::uint32_t f, std::size_t g) const {
    const auto& group = tris_[f].group;
    return group[0] == static_cast<std::int32_t>(g) ? 0 : (group[1] == static_cast<std::int32_t>(g) ? 1 : 2);
  }


  // Step 8 and the degenerate epilogue: slot frames from triangle-corner frames, written
  // straight to the output.
  void resolve() {
    const std::size_t nslots = in_.position.size();
    std::vector<Vec3f>& tangent = out_.tangent;
    std::vector<std::uint8_t>& orient = out_.orientationPreserving;
    tangent.resize(nslots);
    orient.resize(nslots);
    // A slot belongs to one face, so faces can be resolved in parallel. Slots no group reached
    // keep the algorithm's default frame: tangent +x, orientation reversed.
    parallelFor(goodStart_.size() - 1, [&](std::size_t face) {
      const std::uint32_t s0 = in_.faceStart[face], n = in_.faceStart[face + 1] - s0;
      std::array<std::uint8_t, 4> writes{};
      for (std::uint32_t i = 0; i < n; ++i) {
        tangent[s0 + i] = Vec3f{1, 0, 0};
        orient[s0 + i] = 0;
      }
      for (std::size_t t = goodStart_[face]; t < goodStart_[face + 1]; ++t) {
        for (int i = 0; i < 3; ++i) {
          const std::int32_t g = tris_[t].group[i];
          if (g < 0) continue;
          const std::uint32_t c = tris_[t].corner[i];
          const Vec3f ts = cornerSpace_[3 * t + i];
          tangent[s0 + c] = writes[c]++ == 1 ? average(tangent[s0 + c], ts) : ts;
          orient[s0 + c] = groupOrient_[static_cast<std::size_t>(g)];
        }
      }
    });
    if (numGood_ == tris_.size()) return;  // no degenerate triangles

    // Degenerate triangles copy the frame of the first good triangle corner with the same
    // welded vertex; halves of quads whose other half is good are handled below.
    std::vector<std::uint32_t> firstUse(nslots, kNone);
    for (std::size_t j = 3 * numGood_; j-- > 0;) firstUse[vert_[j]] = static_cast<std::uint32_t>(j);
    for (std::size_t t = numGood_; t < tris_.size(); ++t) {
      if (tris_[t].flags & kQuadOneDegenerate) continue;
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t j = firstUse[vert_[3 * t + i]];
        if (j == kNone) continue;
        tangent[slot_[3 * t + i]] = tangent[slot_[j]];
        orient[slot_[3 * t + i]] = orient[slot_[j]];
      }
    }
    // The corner a good half of a quad does not use takes the frame of the corner at the same
    // position.
    for (std::size_t t = 0; t < numGood_; ++t) {
      const Tri& tri = tris_[t];
      if (!(tri.flags & kQuadOneDegenerate)) continue;
      const unsigned used = (1u << tri.corner[0]) | (1u << tri.corner[1]) | (1u << tri.corner[2]);
      int missing = 0;
      while (missing < 4 && (used & (1u << missing))) ++missing;
      if (missing == 4) continue;
      const std::uint32_t s0 = in_.faceStart[static_cast<std::size_t>(tri.face)];
      const Vec3f target = in_.position[s0 + missing];
      for (int i = 0; i < 3; ++i) {
        if (in_.position[s0 + tri.corner[i]] == target) {
          tangent[s0 + missing] = tangent[s0 + tri.corner[i]];
          orient[s0 + missing] = orient[s0 + tri.corner[i]];
          break;
        }
      }
    }
  }

  const Input& in_;
  Output& out_;
  ParallelArray<std::uint32_t> rep_;  // welded vertex (smallest equal slot) of each slot

  std::vector<std::uint32_t> goodStart_;  // #faces+1: face f's good triangles in work order
  ParallelArray<Tri> tris_;               // work order
  ParallelArray<std::uint32_t> slot_;     // 3 per triangle: the slot of each corner
  ParallelArray<std::uint32_t> vert_;     // 3 per triangle: the welded vertex of each corner
  std::size_t numGood_ = 0;

  std::vector<std::uint32_t> groupVertex_;
  std::vector<std::uint8_t> groupOrient_;
  std::vector<std::uint32_t> groupStart_;
  std::vector<std::uint32_t> groupFaces_;

  ParallelArray<Vec3f> cornerSpace_;  // 3 per good triangle: the tangent of its group at each corner
};

}  // namespace

void generate(const Input& input, Output& output) { Engine(input, output).run(); }

}  // namespace sgbake::mikk
