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
#include <limits>
#include <span>

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

template <class F>
void parallelFor(std::size_t n, F&& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
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

std::uint64_t slotHash(const Input& in, std::size_t s) {
  const Vec3f p = in.position[s], n = in.normal[s];
  const Vec2f t = in.uv[s];
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (float x : {p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y}) h = mix(h, canonicalBits(x));
  return h ^ (h >> 32);
}

bool sameVertex(const Input& in, std::size_t a, std::size_t b) {
  return in.position[a] == in.position[b] && in.normal[a] == in.normal[b] && in.uv[a] == in.uv[b];
}

std::vector<std::uint32_t> weld(const Input& in) {
  const std::size_t n = in.position.size();
  std::vector<std::uint64_t> hash(n);
  parallelFor(n, [&](std::size_t s) { hash[s] = slotHash(in, s); });

  // Partition slots by the top bits of their hash (a stable counting sort, so each bucket lists
  // its slots in ascending order), then weld each bucket with its own small hash table.
  constexpr int kBucketBits = 8;
  constexpr std::size_t kBuckets = std::size_t{1} << kBucketBits;
  std::vector<std::uint32_t> bucketStart(kBuckets + 1, 0);
  for (std::size_t s = 0; s < n; ++s) ++bucketStart[(hash[s] >> (64 - kBucketBits)) + 1];
  for (std::size_t b = 0; b < kBuckets; ++b) bucketStart[b + 1] += bucketStart[b];
  std::vector<std::uint32_t> order(n);
  {
    std::vector<std::uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
    for (std::size_t s = 0; s < n; ++s)
      order[fill[hash[s] >> (64 - kBucketBits)]++] = static_cast<std::uint32_t>(s);
  }

  std::vector<std::uint32_t> rep(n);
  tbb::parallel_for(std::size_t{0}, kBuckets, [&](std::size_t b) {
    const std::uint32_t begin = bucketStart[b], end = bucketStart[b + 1];
    if (begin == end) return;
    const std::size_t capacity = std::bit_ceil(std::size_t{2} * (end - begin));
    const std::size_t mask = capacity - 1;
    std::vector<std::uint32_t> table(capacity, kNone);  // first slot of each distinct vertex
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::uint32_t s = order[k];
      for (std::size_t pos = hash[s] & mask;; pos = (pos + 1) & mask) {
        const std::uint32_t head = table[pos];
        if (head == kNone) {
          table[pos] = s;
          rep[s] = s;
          break;
        }
        if (hash[head] == hash[s] && sameVertex(in, head, s)) {
          rep[s] = head;  // slots arrive in ascending order: the head is the smallest
          break;
        }
      }
    }
  });
  return rep;
}

// ---------------------------------------------------------------------------------------------
// Per-triangle state.

struct Tri {
  Vec3f os{}, ot{};          // unit dP/ds, dP/dt (sign-corrected), or zero
  float magS = 0, magT = 0;  // |dP/ds|, |dP/dt|
  std::int32_t face = 0;     // input face
  std::array<std::int32_t, 3> neighbor{kNoTri, kNoTri, kNoTri};  // across edge (i, i+1)
  std::array<std::int32_t, 3> group{-1, -1, -1};                 // group of corner i
  std::array<std::uint8_t, 3> corner{};                         // corner i = face corner
  std::uint8_t flags = 0;
};

// A tangent frame at one slot, as the algorithm accumulates it.
struct TSpace {
  Vec3f os{1, 0, 0};
  float magS = 1;
  Vec3f ot{0, 1, 0};
  float magT = 1;
  int counter = 0;  // how many triangle corners wrote this slot (quad diagonals: 2)
  bool orient = false;
};

TSpace average(const TSpace& a, const TSpace& b) {
  if (a.magS == b.magS && a.magT == b.magT && a.os == b.os && a.ot == b.ot) return a;
  TSpace r;
  r.magS = 0.5f * (a.magS + b.magS);
  r.magT = 0.5f * (a.magT + b.magT);
  r.os = normalizeIfNotZero(a.os + b.os);
  r.ot = normalizeIfNotZero(a.ot + b.ot);
  return r;
}

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
    orderTriangles();
    initTriangles();
    unifyQuadOrientation();
    findNeighbors();
    buildGroups();
    evaluateGroups();
    resolveDegenerates();
    writeOutput();
  }

 private:
  // Step 3/4: split faces into triangles in input order and mark degenerate ones.
  void splitFaces() {
    const std::size_t nf = in_.faceStart.size() - 1;
    std::vector<std::uint32_t> triStart(nf + 1, 0);
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t n = in_.faceStart[f + 1] - in_.faceStart[f];
      triStart[f + 1] = triStart[f] + (n == 4 ? 2 : (n == 3 ? 1 : 0));
    }
    const std::size_t nt = triStart.back();
    inputTris_.resize(nt);
    inputSlots_.resize(3 * nt);
    parallelFor(nf, [&](std::size_t f) {
      const std::uint32_t s0 = in_.faceStart[f];
      const std::uint32_t n = in_.faceStart[f + 1] - s0;
      if (n != 3 && n != 4) return;
      const std::uint32_t t = triStart[f];
      auto emit = [&](std::uint32_t tri, std::array<std::uint8_t, 3> corners) {
        Tri& info = inputTris_[tri];
        info.face = static_cast<std::int32_t>(f);
        info.corner = corners;
        for (int i = 0; i < 3; ++i) inputSlots_[3 * tri + i] = s0 + corners[i];
        const Vec3f p0 = in_.position[s0 + corners[0]], p1 = in_.position[s0 + corners[1]],
                    p2 = in_.position[s0 + corners[2]];
        if (p0 == p1 || p0 == p2 || p1 == p2) info.flags |= kDegenerate;
      };
      if (n == 3) {
        emit(t, {0, 1, 2});
        return;
      }
      if (quadSplitsOn02(s0)) {
        emit(t, {0, 1, 2});
        emit(t + 1, {0, 2, 3});
      } else {
        emit(t, {0, 1, 3});
        emit(t + 1, {1, 2, 3});
      }
      const bool deg0 = inputTris_[t].flags & kDegenerate, deg1 = inputTris_[t + 1].flags & kDegenerate;
      if (deg0 != deg1) {
        inputTris_[t].flags |= kQuadOneDegenerate;
        inputTris_[t + 1].flags |= kQuadOneDegenerate;
      }
    });
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

  // Good triangles first (input order), degenerate ones after.
  void orderTriangles() {
    const std::size_t nt = inputTris_.size();
    std::vector<std::uint32_t> order;
    order.reserve(nt);
    for (std::size_t t = 0; t < nt; ++t)
      if (!(inputTris_[t].flags & kDegenerate)) order.push_back(static_cast<std::uint32_t>(t));
    numGood_ = order.size();
    for (std::size_t t = 0; t < nt; ++t)
      if (inputTris_[t].flags & kDegenerate) order.push_back(static_cast<std::uint32_t>(t));
    tris_.resize(nt);
    slot_.resize(3 * nt);
    vert_.resize(3 * nt);
    parallelFor(nt, [&](std::size_t t) {
      const std::uint32_t src = order[t];
      tris_[t] = inputTris_[src];
      for (int i = 0; i < 3; ++i) {
        slot_[3 * t + i] = inputSlots_[3 * src + i];
        vert_[3 * t + i] = rep_[slot_[3 * t + i]];
      }
    });
    inputTris_ = {};
    inputSlots_ = {};
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
      tri.magS = lenOs / absArea;
      tri.magT = lenOt / absArea;
      if (notZero(tri.magS) && notZero(tri.magT)) tri.flags &= static_cast<std::uint8_t>(~kGroupWithAny);
    });
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
    auto edgeTo = [&](std::size_t e) { return vert_[e - e % 3 + (e % 3 + 1) % 3]; };
    std::vector<std::uint32_t> start(nv + 1, 0);
    for (std::size_t e = 0; e < ne; ++e) ++start[std::min(edgeFrom(e), edgeTo(e)) + 1];
    for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<std::uint32_t> edges(ne);
    {
      std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t e = 0; e < ne; ++e)
        edges[fill[std::min(edgeFrom(e), edgeTo(e))]++] = static_cast<std::uint32_t>(e);
    }
    parallelFor(nv, [&](std::size_t v) {
      const auto begin = edges.begin() + start[v], end = edges.begin() + start[v + 1];
      if (end - begin < 2) return;
      auto larger = [&](std::uint32_t e) { return std::max(edgeFrom(e), edgeTo(e)); };
      std::stable_sort(begin, end, [&](std::uint32_t x, std::uint32_t y) { return larger(x) < larger(y); });
      for (auto a = begin; a != end; ++a) {
        const std::uint32_t ea = *a;
        if (tris_[ea / 3].neighbor[ea % 3] != kNoTri) continue;
        for (auto b = a + 1; b != end && larger(*b) == larger(ea); ++b) {
          const std::uint32_t eb = *b;
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

  // Step 7: a frame per (group, triangle corner).
  void evaluateGroups() {
    cornerSpace_.assign(3 * numGood_, TSpace{});
    const std::size_t ng = groupVertex_.size();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ng, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<std::uint32_t> members;
                        std::vector<std::vector<std::uint32_t>> subgroups;
                        std::vector<TSpace> subgroupSpaces;
                        for (std::size_t g = r.begin(); g != r.end(); ++g)
                          evaluateGroup(g, members, subgroups, subgroupSpaces);
                      });
  }

  void evaluateGroup(std::size_t g, std::vector<std::uint32_t>& members,
                     std::vector<std::vector<std::uint32_t>>& subgroups,
                     std::vector<TSpace>& subgroupSpaces) {
    // Sub-groups split triangles whose projected derivatives point in opposite directions: the
    // default angular threshold of 180 degrees, cos = -1.
    constexpr float kThresholdCos = -1.0f;
    const std::uint32_t vertex = groupVertex_[g];
    const Vec3f n = in_.normal[vertex];
    const auto faces = std::span(groupFaces_).subspan(groupStart_[g], groupStart_[g + 1] - groupStart_[g]);
    std::size_t numSubgroups = 0;
    for (const std::uint32_t f : faces) {
      const Tri& tri = tris_[f];
      const int index = tri.group[0] == static_cast<std::int32_t>(g)   ? 0
                        : tri.group[1] == static_cast<std::int32_t>(g) ? 1
                                                                        : 2;
      const Vec3f os = projectNormalized(tri.os, n), ot = projectNormalized(tri.ot, n);
      members.clear();
      for (const std::uint32_t t : faces) {
        const Tri& other = tris_[t];
        const bool any = (tri.flags | other.flags) & kGroupWithAny;
        const bool sameFace = tri.face == other.face;
        if (any || sameFace ||
            (dot(os, projectNormalized(other.os, n)) > kThresholdCos &&
             dot(ot, projectNormalized(other.ot, n)) > kThresholdCos))
          members.push_back(t);
      }
      std::sort(members.begin(), members.end());
      std::size_t l = 0;
      while (l < numSubgroups && subgroups[l] != members) ++l;
      if (l == numSubgroups) {
        if (subgroups.size() <= l) {
          subgroups.emplace_back();
          subgroupSpaces.emplace_back();
        }
        subgroups[l] = members;
        subgroupSpaces[l] = evalSpace(members, vertex);
        ++numSubgroups;
      }
      TSpace ts = subgroupSpaces[l];
      ts.orient = groupOrient_[g];
      cornerSpace_[3 * f + index] = ts;
    }
  }

  // The angle-weighted average of the members' derivatives at @p vertex.
  TSpace evalSpace(const std::vector<std::uint32_t>& members, std::uint32_t vertex) const {
    TSpace r;
    r.os = r.ot = Vec3f{0, 0, 0};
    r.magS = r.magT = 0;
    float angleSum = 0;
    for (const std::uint32_t f : members) {
      const Tri& tri = tris_[f];
      if (tri.flags & kGroupWithAny) continue;
      const int i = cornerOf(f, vertex);
      assert(i >= 0);
      const Vec3f n = in_.normal[vert_[3 * f + i]];
      const Vec3f os = projectNormalized(tri.os, n), ot = projectNormalized(tri.ot, n);
      const Vec3f p0 = in_.position[vert_[3 * f + (i > 0 ? i - 1 : 2)]];
      const Vec3f p1 = in_.position[vert_[3 * f + i]];
      const Vec3f p2 = in_.position[vert_[3 * f + (i < 2 ? i + 1 : 0)]];
      const Vec3f e1 = projectNormalized(p0 - p1, n), e2 = projectNormalized(p2 - p1, n);
      const float angle = safeAcos(dot(e1, e2));
      r.os += angle * os;
      r.ot += angle * ot;
      r.magS += angle * tri.magS;
      r.magT += angle * tri.magT;
      angleSum += angle;
    }
    r.os = normalizeIfNotZero(r.os);
    r.ot = normalizeIfNotZero(r.ot);
    if (angleSum > 0) {
      r.magS /= angleSum;
      r.magT /= angleSum;
    }
    return r;
  }

  // Step 8 and the degenerate epilogue: slot frames from triangle-corner frames.
  void resolveDegenerates() {
    slotSpace_.assign(in_.position.size(), TSpace{});
    for (std::size_t t = 0; t < numGood_; ++t) {
      for (int i = 0; i < 3; ++i) {
        if (tris_[t].group[i] < 0) continue;
        TSpace& out = slotSpace_[slot_[3 * t + i]];
        const TSpace& ts = cornerSpace_[3 * t + i];
        const bool orient = ts.orient;
        if (out.counter == 1) {
          out = average(out, ts);
          out.counter = 2;
        } else {
          out = ts;
          out.counter = 1;
        }
        out.orient = orient;
      }
    }

    // Degenerate triangles copy the frame of the first good triangle corner with the same
    // welded vertex; halves of quads whose other half is good are handled below.
    std::vector<std::uint32_t> firstUse(in_.position.size(), kNone);
    for (std::size_t j = 3 * numGood_; j-- > 0;) firstUse[vert_[j]] = static_cast<std::uint32_t>(j);
    for (std::size_t t = numGood_; t < tris_.size(); ++t) {
      if (tris_[t].flags & kQuadOneDegenerate) continue;
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t j = firstUse[vert_[3 * t + i]];
        if (j != kNone) slotSpace_[slot_[3 * t + i]] = slotSpace_[slot_[j]];
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
          slotSpace_[s0 + missing] = slotSpace_[s0 + tri.corner[i]];
          break;
        }
      }
    }
  }

  void writeOutput() {
    const std::size_t n = slotSpace_.size();
    out_.tangent.resize(n);
    out_.orientationPreserving.resize(n);
    parallelFor(n, [&](std::size_t s) {
      out_.tangent[s] = slotSpace_[s].os;
      out_.orientationPreserving[s] = slotSpace_[s].orient ? 1 : 0;
    });
  }

  const Input& in_;
  Output& out_;
  std::vector<std::uint32_t> rep_;  // welded vertex (smallest equal slot) of each slot

  std::vector<Tri> inputTris_;            // input order (temporary)
  std::vector<std::uint32_t> inputSlots_;  // input order (temporary)
  std::vector<Tri> tris_;                 // work order
  std::vector<std::uint32_t> slot_;       // 3 per triangle: the slot of each corner
  std::vector<std::uint32_t> vert_;       // 3 per triangle: the welded vertex of each corner
  std::size_t numGood_ = 0;

  std::vector<std::uint32_t> groupVertex_;
  std::vector<bool> groupOrient_;
  std::vector<std::uint32_t> groupStart_;
  std::vector<std::uint32_t> groupFaces_;

  std::vector<TSpace> cornerSpace_;  // 3 per good triangle
  std::vector<TSpace> slotSpace_;
};

}  // namespace

void generate(const Input& input, Output& output) { Engine(input, output).run(); }

}  // namespace sgbake::mikk
