// cohfrac — point queries against triangle meshes, behind the C
// header cf_fcl.h.  FCL builds, refits and owns the bounding-volume
// hierarchy (BVHModel<OBBRSS>, or BVHModel<AABB> for a deforming mesh) and
// runs the branch-and-bound distance traversal; the leaf test (exact closest
// point on one triangle) and the sign (angle-weighted pseudo-normals,
// Baerentzen & Aanaes 2005) are ours.
//
// Why not fcl::distance with a small sphere: FCL 0.7's mesh-sphere leaf test
// (meshShapeDistanceOrientedNodeLeafTesting -> sphereTriangleDistance with
// nearest points) leaves the distance uninitialised when the sphere touches
// the triangle, i.e. for any point within the sphere's radius of the mesh -
// a point lying on the surface included - and then feeds it to
// DistanceResult::update.  Our node replaces that leaf test and the
// sphere-bound BV test with exact point queries.
//
// FCL's headers throw (std::logic_error in the GJK code, std::bad_alloc from
// new), so this file is compiled with -fexceptions (see CMakeLists.txt) and
// every entry point catches everything: no exception leaves this file.
#include "cf_fcl.h"

#include <fcl/math/bv/utility.h>  // fit(), used by BVHModel::refitTree
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/AABB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>
#include <fcl/narrowphase/detail/traversal/distance/bvh_shape_distance_traversal_node.h>
#include <fcl/narrowphase/distance_result.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace {

thread_local char g_error[256] = "";

void set_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(g_error, sizeof g_error, fmt, ap);
    va_end(ap);
}

typedef fcl::Vector3d V3;
// Static meshes get oriented boxes (tight, for many queries); deforming
// ones axis-aligned boxes, whose refit after every move is cheap (refitting
// oriented boxes fits each by an eigen-decomposition).
typedef fcl::BVHModel<fcl::OBBRSSd> ObbModel;
typedef fcl::BVHModel<fcl::AABBd> BoxModel;

// Barycentric coordinates below this count as 0 when classifying the
// closest point: a vertex or edge is then preferred to a neighbouring edge
// or face, so that round-off cannot hand the sign test a feature whose
// pseudo-normal does not apply.
const double BARY_TOL = 1e-10;

// Closest point of triangle (a, b, c) to p, by Voronoi regions (Ericson,
// Real-Time Collision Detection 5.1.5).  Returns q and its barycentric
// coordinates (q = l[0] a + l[1] b + l[2] c), exact 0/1 in vertex and edge
// regions.
V3 closest_on_triangle(const V3 &p, const V3 &a, const V3 &b, const V3 &c, double l[3])
{
    const V3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) {
        l[0] = 1, l[1] = 0, l[2] = 0;
        return a;
    }
    const V3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) {
        l[0] = 0, l[1] = 1, l[2] = 0;
        return b;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double t = d1 / (d1 - d3);
        l[0] = 1 - t, l[1] = t, l[2] = 0;
        return a + t * ab;
    }
    const V3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) {
        l[0] = 0, l[1] = 0, l[2] = 1;
        return c;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double t = d2 / (d2 - d6);
        l[0] = 1 - t, l[1] = 0, l[2] = t;
        return a + t * ac;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        l[0] = 0, l[1] = 1 - t, l[2] = t;
        return b + t * (c - b);
    }
    const double s = 1.0 / (va + vb + vc);
    const double v = vb * s, w = vc * s;
    l[0] = 1 - v - w, l[1] = v, l[2] = w;
    return a + v * ab + w * ac;
}

// Exact distance from a point to an oriented box: a lower bound for every
// triangle inside the node.
double point_obb_distance(const fcl::OBBd &obb, const V3 &p)
{
    const V3 d = p - obb.To;
    double s2 = 0.0;
    for (int i = 0; i < 3; ++i) {
        const double x = std::fabs(obb.axis.col(i).dot(d)) - obb.extent[i];
        if (x > 0) s2 += x * x;
    }
    return std::sqrt(s2);
}

// Lower bounds of the distance from p to any triangle inside a node.
double bv_distance(const fcl::OBBRSSd &bv, const V3 &p) { return point_obb_distance(bv.obb, p); }

double bv_distance(const fcl::AABBd &bv, const V3 &p)
{
    double s2 = 0.0;
    for (int i = 0; i < 3; ++i) {
        const double x = std::max(bv.min_[i] - p[i], p[i] - bv.max_[i]);
        if (x > 0) s2 += x * x;
    }
    return std::sqrt(s2);
}

}  // namespace

struct cff_mesh {
    std::unique_ptr<ObbModel> obb;  // static mesh: its hierarchy
    std::unique_ptr<BoxModel> box;  // deforming mesh: its hierarchy
    std::vector<V3> v;            // vertices
    std::vector<int> t;           // [nt][3]
    std::vector<V3> face_n;       // unit normal per triangle
    std::vector<int> edge_of;     // [nt][3]: edge k (corners k, k+1) -> unique edge
    std::vector<V3> edge_n;       // per unique edge; zero when undefined
    std::vector<V3> vert_n;       // per vertex; zero when undefined
    V3 center;                    // of the vertices' bounding box
    double size;                  // its diagonal
};

namespace {

// Point query as an FCL distance traversal over the mesh's BVH.  The result
// keeps the nearest triangle in b1 and the closest point in nearest_points[0].
template <typename BV>
class PointNode : public fcl::detail::BVHShapeDistanceTraversalNode<BV, fcl::Sphered> {
public:
    using fcl::detail::BVHShapeDistanceTraversalNode<BV, fcl::Sphered>::model1;
    using fcl::detail::BVHShapeDistanceTraversalNode<BV, fcl::Sphered>::model2;
    using fcl::detail::BVHShapeDistanceTraversalNode<BV, fcl::Sphered>::result;
    PointNode(const cff_mesh *m, const V3 &p, double s) : mesh(m), point(p), slack(s) {}

    // Lower bound for the node, less the round-off of computing it, so
    // that no triangle is pruned by a bound a few ulps too high.
    double BVTesting(int b1, int) const override
    {
        return bv_distance(model1->getBV(b1).bv, point) - slack;
    }

    void leafTesting(int b1, int) const override
    {
        const int tri = model1->getBV(b1).primitiveId();
        const int *ti = &mesh->t[3 * static_cast<size_t>(tri)];
        double l[3];
        const V3 q =
            closest_on_triangle(point, mesh->v[ti[0]], mesh->v[ti[1]], mesh->v[ti[2]], l);
        const double d = (point - q).norm();
        if (d < result->min_distance)
            result->update(d, model1, model2, tri, fcl::DistanceResultd::NONE, q, point);
    }

    bool canStop(double c) const override { return c >= result->min_distance; }

    const cff_mesh *mesh;
    V3 point;
    double slack;
};

// Nonzero sum, normalised; zero vector when the sum vanishes.
V3 unit_or_zero(const V3 &s)
{
    const double n = s.norm();
    return n > 0 ? V3(s / n) : V3::Zero();
}

// Bounding box, face normals and pseudo-normals from the current vertices.
// Edge: sum of the normals of the triangles sharing it (each sees it under
// the angle pi).  Vertex: normals weighted by the triangle's angle at the
// vertex.  A triangle of zero area (repeated or collinear corners) has no
// normal: it keeps its previous one (zero on the first call).  Returns the
// first such triangle, or -1.
int compute_normals(cff_mesh *m)
{
    const size_t nv = m->v.size(), nt = m->face_n.size();
    V3 lo = m->v[0], hi = m->v[0];
    for (size_t i = 1; i < nv; ++i) {
        lo = lo.cwiseMin(m->v[i]);
        hi = hi.cwiseMax(m->v[i]);
    }
    m->center = 0.5 * (lo + hi);
    m->size = (hi - lo).norm();
    int bad = -1;
    for (size_t t = 0; t < nt; ++t) {
        const int *ti = &m->t[3 * t];
        const V3 &a = m->v[ti[0]], &b = m->v[ti[1]], &c = m->v[ti[2]];
        const V3 cr = (b - a).cross(c - a);
        if (cr.norm() > 1e-12 * (b - a).norm() * (c - a).norm()) m->face_n[t] = cr.normalized();
        else if (bad < 0) bad = static_cast<int>(t);
    }
    std::fill(m->edge_n.begin(), m->edge_n.end(), V3::Zero());
    std::fill(m->vert_n.begin(), m->vert_n.end(), V3::Zero());
    for (size_t t = 0; t < nt; ++t) {
        const int *ti = &m->t[3 * t];
        for (int k = 0; k < 3; ++k) {
            const int i = ti[k], j = ti[(k + 1) % 3], h = ti[(k + 2) % 3];
            m->edge_n[m->edge_of[3 * t + k]] += m->face_n[t];
            const V3 e1 = m->v[j] - m->v[i], e2 = m->v[h] - m->v[i];
            const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
            m->vert_n[i] += angle * m->face_n[t];
        }
    }
    for (V3 &e : m->edge_n) e = unit_or_zero(e);
    for (V3 &n : m->vert_n) n = unit_or_zero(n);
    return bad;
}

template <typename BV>
bool build(fcl::BVHModel<BV> &b, const std::vector<V3> &v, const std::vector<fcl::Triangle> &t)
{
    return b.beginModel(static_cast<int>(t.size()), static_cast<int>(v.size())) == fcl::BVH_OK &&
           b.addSubModel(v, t) == fcl::BVH_OK && b.endModel() == fcl::BVH_OK;
}

cff_mesh *create(const double *verts, int nv, const int *tris, int nt, bool deforming)
{
    if (!verts || nv < 3 || !tris || nt < 1) {
        set_error("mesh needs >= 3 vertices and >= 1 triangle (got %d, %d)", verts ? nv : 0,
                  tris ? nt : 0);
        return NULL;
    }
    for (int i = 0; i < 3 * nv; ++i) {
        if (!std::isfinite(verts[i])) {
            set_error("mesh vertex %d is non-finite", i / 3);
            return NULL;
        }
    }
    for (int t = 0; t < nt; ++t) {
        for (int k = 0; k < 3; ++k) {
            const int i = tris[3 * t + k];
            if (i < 0 || i >= nv) {
                set_error("triangle %d: vertex index %d out of range [0, %d)", t, i, nv);
                return NULL;
            }
        }
    }

    std::unique_ptr<cff_mesh> m(new cff_mesh());
    m->v.resize(static_cast<size_t>(nv));
    for (int i = 0; i < nv; ++i) m->v[i] = V3(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2]);
    m->t.assign(tris, tris + 3 * static_cast<size_t>(nt));
    // Each triangle edge's unique edge, for the edge pseudo-normals.
    std::map<std::pair<int, int>, int> edge_index;
    m->edge_of.resize(3 * static_cast<size_t>(nt));
    for (int t = 0; t < nt; ++t) {
        for (int k = 0; k < 3; ++k) {
            const int i = tris[3 * t + k], j = tris[3 * t + (k + 1) % 3];
            const std::pair<int, int> key(std::min(i, j), std::max(i, j));
            const int next = static_cast<int>(edge_index.size());
            m->edge_of[3 * t + k] = edge_index.insert(std::make_pair(key, next)).first->second;
        }
    }
    m->edge_n.resize(edge_index.size());
    m->face_n.assign(static_cast<size_t>(nt), V3::Zero());
    m->vert_n.resize(static_cast<size_t>(nv));
    int bad = compute_normals(m.get());
    if (bad >= 0) {
        set_error("triangle %d is degenerate (zero area)", bad);
        return NULL;
    }

    std::vector<fcl::Triangle> ftris(static_cast<size_t>(nt));
    for (int t = 0; t < nt; ++t)
        ftris[t] = fcl::Triangle(tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]);
    if (deforming) m->box.reset(new BoxModel());
    else m->obb.reset(new ObbModel());
    if (!(deforming ? build(*m->box, m->v, ftris) : build(*m->obb, m->v, ftris))) {
        set_error("FCL could not build the bounding-volume hierarchy");
        return NULL;
    }
    return m.release();
}

template <typename BV>
void traverse(const fcl::BVHModel<BV> *model, const cff_mesh *m, const V3 &point, double slack,
              fcl::DistanceResultd *result)
{
    PointNode<BV> node(m, point, slack);
    node.model1 = model;
    node.request = fcl::DistanceRequestd(true);  // nearest points
    node.result = result;
    fcl::detail::distance(&node, NULL, 2);
}

int closest(const cff_mesh *m, const double p[3], double max_dist, double q[3], double n[3],
            double *d, int *tri_out, double bary[3])
{
    if (!m || !p || !q || !n || !d) {
        set_error("cff_mesh_closest: NULL argument");
        return -1;
    }
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        set_error("query point is non-finite");
        return -1;
    }
    if (std::isnan(max_dist) || max_dist < 0.0) {
        set_error("max_dist must be >= 0 (got %g)", max_dist);
        return -1;
    }
    const V3 point(p[0], p[1], p[2]);
    // Round-off of distances near p: box bounds and the closest point on a
    // triangle are both computed from coordinates of this size.
    const double slack = 1e-12 * (m->size + (point - m->center).norm());
    // Start the search with the bound itself: FCL then prunes every node
    // farther than max_dist, and finds nothing when the whole mesh is.  A
    // point on the surface must be found with max_dist = 0, whose distance
    // comes out as round-off: hence the slack.
    const double limit = max_dist + slack;
    fcl::DistanceResultd result(std::isfinite(limit) ? limit : std::numeric_limits<double>::max());
    if (m->obb) traverse(m->obb.get(), m, point, slack, &result);
    else traverse(m->box.get(), m, point, slack, &result);
    if (result.b1 == fcl::DistanceResultd::NONE) return 0;

    const int tri = result.b1;
    const int *ti = &m->t[3 * static_cast<size_t>(tri)];
    double l[3];
    const V3 qq = closest_on_triangle(point, m->v[ti[0]], m->v[ti[1]], m->v[ti[2]], l);
    // Closest feature: a vertex (two coordinates ~0), an edge (one) or the face.
    const bool z[3] = {l[0] < BARY_TOL, l[1] < BARY_TOL, l[2] < BARY_TOL};
    const int nz = z[0] + z[1] + z[2];
    V3 normal = m->face_n[tri];
    if (nz >= 2) {
        const int k = !z[0] ? 0 : (!z[1] ? 1 : 2);
        if (m->vert_n[ti[k]].squaredNorm() > 0) normal = m->vert_n[ti[k]];
    } else if (nz == 1) {
        // Coordinate k ~ 0: the edge opposite corner k joins corners k+1, k+2.
        const int k = z[0] ? 0 : (z[1] ? 1 : 2);
        const V3 &en = m->edge_n[m->edge_of[3 * static_cast<size_t>(tri) + (k + 1) % 3]];
        if (en.squaredNorm() > 0) normal = en;
    }
    const V3 diff = point - qq;
    const double dist = diff.norm();
    for (int i = 0; i < 3; ++i) {
        q[i] = qq[i];
        n[i] = normal[i];
    }
    *d = diff.dot(normal) < 0 ? -dist : dist;
    if (tri_out) *tri_out = tri;
    if (bary)
        for (int i = 0; i < 3; ++i) bary[i] = l[i];
    return 1;
}

template <typename BV>
bool refit(fcl::BVHModel<BV> &b, const std::vector<V3> &v)
{
    if (b.beginUpdateModel() != fcl::BVH_OK) return false;
    for (const V3 &x : v) b.updateVertex(x);
    return b.endUpdateModel(true, true) == fcl::BVH_OK;
}

int update(cff_mesh *m, const double *verts)
{
    if (!m || !verts) {
        set_error("cff_mesh_update: NULL argument");
        return -1;
    }
    const size_t nv = m->v.size();
    for (size_t i = 0; i < 3 * nv; ++i) {
        if (!std::isfinite(verts[i])) {
            set_error("mesh vertex %zu is non-finite", i / 3);
            return -1;
        }
    }
    for (size_t i = 0; i < nv; ++i) m->v[i] = V3(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2]);
    if (!(m->obb ? refit(*m->obb, m->v) : refit(*m->box, m->v))) {
        set_error("FCL could not refit the hierarchy");
        return -1;
    }
    compute_normals(m);
    return 0;
}

// FCL's arrays: vertices (twice once refitted: the previous frame's are
// kept), triangles, bounding-volume nodes, primitive indices.
template <typename BV>
size_t model_bytes(const fcl::BVHModel<BV> &b)
{
    return (size_t)b.num_vertices * sizeof(fcl::Vector3d) * (b.prev_vertices ? 2 : 1) +
           (size_t)b.num_tris * (sizeof(fcl::Triangle) + sizeof(unsigned int)) +
           (size_t)b.getNumBVs() * sizeof(fcl::BVNode<BV>);
}

// create() with every exception caught: none may leave this file.
cff_mesh *create_caught(const double *verts, int nv, const int *tris, int nt, bool deforming)
{
    try {
        return create(verts, nv, tris, nt, deforming);
    } catch (const std::bad_alloc &) {
        set_error("out of memory");
    } catch (const std::exception &e) {
        set_error("FCL: %s", e.what());
    } catch (...) {
        set_error("FCL: unknown exception");
    }
    return NULL;
}

}  // namespace

extern "C" {

cff_mesh *cff_mesh_create(const double *verts, int nv, const int *tris, int nt)
{
    return create_caught(verts, nv, tris, nt, false);
}

cff_mesh *cff_mesh_create_deforming(const double *verts, int nv, const int *tris, int nt)
{
    return create_caught(verts, nv, tris, nt, true);
}

size_t cff_mesh_bytes(const cff_mesh *m)
{
    if (!m)
        return 0;
    return sizeof *m + (m->obb ? model_bytes(*m->obb) : model_bytes(*m->box)) +
           m->v.capacity() * sizeof(V3) + m->t.capacity() * sizeof(int) +
           m->edge_of.capacity() * sizeof(int) +
           (m->face_n.capacity() + m->edge_n.capacity() + m->vert_n.capacity()) * sizeof(V3);
}

void cff_mesh_destroy(cff_mesh *m)
{
    try {
        delete m;
    } catch (...) {
    }
}

int cff_mesh_closest(const cff_mesh *m, const double p[3], double max_dist, double q[3],
                     double n[3], double *d)
{
    return cff_mesh_closest_tri(m, p, max_dist, q, n, d, NULL, NULL);
}

int cff_mesh_closest_tri(const cff_mesh *m, const double p[3], double max_dist, double q[3],
                         double n[3], double *d, int *tri, double bary[3])
{
    try {
        return closest(m, p, max_dist, q, n, d, tri, bary);
    } catch (const std::exception &e) {
        set_error("FCL: %s", e.what());
    } catch (...) {
        set_error("FCL: unknown exception");
    }
    return -1;
}

int cff_mesh_update(cff_mesh *m, const double *verts)
{
    try {
        return update(m, verts);
    } catch (const std::bad_alloc &) {
        set_error("out of memory");
    } catch (const std::exception &e) {
        set_error("FCL: %s", e.what());
    } catch (...) {
        set_error("FCL: unknown exception");
    }
    return -1;
}

const char *cff_last_error(void) { return g_error; }

}  // extern "C"
