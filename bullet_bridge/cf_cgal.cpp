// cohfrac — surface repair with CGAL's Polygon Mesh Processing, behind the
// C header cf_cgal.h.  Every step is CGAL's; this file only chains them,
// counts what each changed and copies the result out.
//
// The kernel is Epeck (exact predicates and constructions): autorefinement
// constructs the intersection points of triangles, and with inexact
// constructions those points can create new intersections.  CGAL throws
// (std::bad_alloc, CGAL's precondition and assertion failures on input it
// refuses), so this file is compiled with -fexceptions (CMakeLists.txt) and
// the entry point catches everything.
#include "cf_cgal.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/alpha_wrap_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <array>
#include <new>
#include <utility>
#include <vector>

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

typedef CGAL::Exact_predicates_exact_constructions_kernel K;
typedef K::Point_3 Point;
typedef CGAL::Surface_mesh<Point> Mesh;
typedef std::vector<std::size_t> Polygon;
typedef CGAL::Exact_predicates_inexact_constructions_kernel Ki;
typedef CGAL::Surface_mesh<Ki::Point_3> Mesh_inexact;

thread_local char g_error[512];

void set_error(const char *what) { std::snprintf(g_error, sizeof g_error, "%s", what); }

// Triangles that orient_polygon_soup turned: the corners' positions now go
// round the other way.
int count_reoriented(const std::vector<Point> &before_pts, const std::vector<Polygon> &before,
                     const std::vector<Point> &pts, const std::vector<Polygon> &after)
{
    int n = 0;
    for (std::size_t i = 0; i < after.size() && i < before.size(); i++) {
        const Polygon &a = after[i], &b = before[i];
        if (a.size() != 3 || b.size() != 3)
            continue;
        bool same = false;
        for (int s = 0; s < 3 && !same; s++)
            same = pts[a[0]] == before_pts[b[s]] && pts[a[1]] == before_pts[b[(s + 1) % 3]] &&
                   pts[a[2]] == before_pts[b[(s + 2) % 3]];
        n += !same;
    }
    return n;
}

// Close each border cycle of the mesh with triangles; the count of cycles.
int fill_holes(Mesh &m)
{
    std::vector<Mesh::Halfedge_index> borders;
    PMP::extract_boundary_cycles(m, std::back_inserter(borders));
    int n = 0;
    for (Mesh::Halfedge_index h : borders) {
        std::vector<Mesh::Face_index> added;
        PMP::triangulate_hole(m, h, std::back_inserter(added));
        n += !added.empty();
    }
    return n;
}

// The union of the mesh's connected components, when each is a closed
// surface free of self-intersections on its own (the overlapping parts of
// a multi-body model): corefinement, the robust Boolean of CGAL.
bool union_of_components(Mesh &m)
{
    std::vector<Mesh> parts;
    PMP::split_connected_components(m, parts);
    if (parts.size() < 2)
        return false;
    for (Mesh &p : parts) {
        if (!CGAL::is_closed(p) || PMP::does_self_intersect(p))
            return false;
        if (!PMP::is_outward_oriented(p))
            PMP::reverse_face_orientations(p);
    }
    Mesh sum = parts[0];
    for (std::size_t i = 1; i < parts.size(); i++) {
        Mesh out;
        if (!PMP::corefine_and_compute_union(sum, parts[i], out))
            return false;
        sum = std::move(out);
    }
    m = std::move(sum);
    return !PMP::does_self_intersect(m);
}

// One way to remove the self-intersections on a copy of the mesh; the mesh
// is replaced only when it succeeded.  CGAL's experimental autorefinement
// throws on configurations it cannot handle (this file keeps CGAL's
// assertions on): that is a failure of this way only.
template <class Repair> bool attempt(Mesh &m, Repair how)
{
    Mesh work = m;
    try {
        if (!how(work))
            return false;
    } catch (const std::bad_alloc &) {
        throw;
    } catch (...) {
        return false;
    }
    work.collect_garbage();
    m = std::move(work);
    return true;
}

// Removes the self-intersections of m: the union of its parts when they
// overlap as separate closed surfaces; else autorefinement, which cuts the
// surface along its intersections and removes the patches inside.
// Returns the way that worked (cfc_repair_report.intersections_fixed), or
// CFC_NOT_FIXED with m unchanged.
int remove_intersections(Mesh &m)
{
    if (attempt(m, union_of_components))
        return CFC_FIXED_BY_UNION;
    if (attempt(m, [](Mesh &w) {
            return PMP::experimental::autorefine_and_remove_self_intersections(w) &&
                   CGAL::is_closed(w) && !PMP::does_self_intersect(w);
        }))
        return CFC_FIXED_BY_AUTOREFINE;
    return CFC_NOT_FIXED;
}

// The exact repair: the soup oriented as one surface without splitting any
// vertex, holes filled, self-intersections removed.  False when any step
// cannot be done that way (then the caller wraps the soup instead).
bool repair_exactly(std::vector<Point> pts, std::vector<Polygon> polys, Mesh &m,
                    cfc_repair_report &r)
{
    if (!PMP::is_polygon_soup_a_polygon_mesh(polys)) {
        std::vector<Point> pts0 = pts;
        std::vector<Polygon> polys0 = polys;
        if (!PMP::orient_polygon_soup(pts, polys)) /* it had to split vertices or edges */
            return false;
        r.faces_reoriented = count_reoriented(pts0, polys0, pts, polys);
    }
    PMP::polygon_soup_to_polygon_mesh(pts, polys, m);
    if (!CGAL::is_closed(m)) {
        PMP::stitch_borders(m);
        r.holes_filled = fill_holes(m);
        if (!CGAL::is_closed(m))
            return false;
    }
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
    PMP::self_intersections(m, std::back_inserter(pairs));
    r.intersecting_pairs = (int)pairs.size();
    r.intersections_fixed = pairs.empty() ? CFC_NONE_FOUND : remove_intersections(m);
    if (r.intersections_fixed == CFC_NOT_FIXED)
        return false;
    PMP::orient_to_bound_a_volume(m);
    return true;
}

// The diagonal of the points' bounding box.
double diagonal(const std::vector<Ki::Point_3> &p)
{
    CGAL::Bbox_3 box;
    for (const Ki::Point_3 &q : p)
        box += q.bbox();
    return std::sqrt(CGAL::square(box.xmax() - box.xmin()) +
                     CGAL::square(box.ymax() - box.ymin()) +
                     CGAL::square(box.zmax() - box.zmin()));
}

template <class P> std::vector<Ki::Point_3> inexact(const std::vector<P> &pts)
{
    std::vector<Ki::Point_3> p;
    p.reserve(pts.size());
    for (const P &q : pts)
        p.emplace_back(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
    return p;
}

// Copies a triangle mesh out as malloc'd arrays; -1 when out of memory or
// when a face is not a triangle.
template <class M> int copy_out(const M &m, double **v_out, int *nv_out, int **tri_out, int *nt_out)
{
    int nvo = (int)m.number_of_vertices(), nto = (int)m.number_of_faces();
    if (nto == 0) {
        set_error("no triangle is left after the repair");
        return -1;
    }
    double *v = (double *)std::malloc((std::size_t)nvo * 3 * sizeof(double));
    int *tri = (int *)std::malloc((std::size_t)nto * 3 * sizeof(int));
    if (!v || !tri) {
        std::free(v);
        std::free(tri);
        set_error("out of memory copying the repaired surface");
        return -1;
    }
    for (typename M::Vertex_index vi : m.vertices())
        for (int k = 0; k < 3; k++)
            v[3 * (std::size_t)vi + k] = CGAL::to_double(m.point(vi)[k]);
    int t = 0;
    for (typename M::Face_index f : m.faces()) {
        int k = 0;
        for (typename M::Vertex_index vi : CGAL::vertices_around_face(m.halfedge(f), m))
            if (k < 3)
                tri[3 * t + k++] = (int)(std::size_t)vi;
        if (k != 3) {
            std::free(v);
            std::free(tri);
            set_error("the repaired surface has a face that is not a triangle");
            return -1;
        }
        t++;
    }
    *v_out = v, *nv_out = nvo, *tri_out = tri, *nt_out = nto;
    return 0;
}

int repair(const double *verts, int nv, const int *tris, int nt, double **v_out, int *nv_out,
           int **tri_out, int *nt_out, cfc_repair_report *rep)
{
    std::vector<Point> pts;
    pts.reserve((std::size_t)nv);
    for (int i = 0; i < nv; i++)
        pts.emplace_back(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2]);
    std::vector<Polygon> polys((std::size_t)nt);
    for (int t = 0; t < nt; t++)
        polys[(std::size_t)t] = {(std::size_t)tris[3 * t], (std::size_t)tris[3 * t + 1],
                                 (std::size_t)tris[3 * t + 2]};
    cfc_repair_report r = {};
    r.faces_in = nt;
    PMP::repair_polygon_soup(pts, polys);
    r.points_merged = nv - (int)pts.size();
    r.faces_removed = nt - (int)polys.size();
    if (polys.empty()) {
        set_error("no triangle is left after removing the degenerate and repeated ones");
        return -1;
    }
    Mesh m;
    int st;
    if (repair_exactly(pts, polys, m, r)) {
        m.collect_garbage();
        st = copy_out(m, v_out, nv_out, tri_out, nt_out);
    } else {
        std::vector<Ki::Point_3> p = inexact(pts);
        double diag = diagonal(p);
        r.wrap_alpha = diag / CFC_WRAP_ALPHA_DIVISOR;
        r.wrap_offset = diag / CFC_WRAP_OFFSET_DIVISOR;
        r.intersections_fixed = CFC_WRAPPED;
        r.faces_reoriented = r.holes_filled = 0;
        // CGAL's 3D alpha wrapping of the soup: a closed, oriented 2-manifold
        // free of self-intersections that encloses every triangle at the
        // offset, whatever the input's defects (Portaneri et al., ACM TOG
        // 2022); features thinner than about alpha are closed over.
        Mesh_inexact w;
        CGAL::alpha_wrap_3(p, polys, r.wrap_alpha, r.wrap_offset, w);
        st = copy_out(w, v_out, nv_out, tri_out, nt_out);
    }
    if (st != 0)
        return st;
    r.faces_out = *nt_out;
    *rep = r;
    return 0;
}

}  // namespace

// The surface as a soup of points and triangles (inexact kernel): what
// alpha wrapping and remeshing start from.
static void triangle_soup(const double *verts, int nv, const int *tris, int nt,
                          std::vector<Ki::Point_3> &p, std::vector<std::array<std::size_t, 3>> &f)
{
    p.reserve((std::size_t)nv);
    for (int i = 0; i < nv; i++)
        p.emplace_back(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2]);
    f.resize((std::size_t)nt);
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            f[(std::size_t)t][(std::size_t)k] = (std::size_t)tris[3 * t + k];
}

extern "C" {

int cfc_repair_surface(const double *verts, int nv, const int *tris, int nt, double **v_out,
                       int *nv_out, int **tri_out, int *nt_out, cfc_repair_report *rep)
{
    if (!verts || !tris || !v_out || !nv_out || !tri_out || !nt_out || !rep || nv < 3 ||
        nt < 1) {
        set_error("cfc_repair_surface: no surface given");
        return -1;
    }
    for (int i = 0; i < 3 * nv; i++)
        if (!std::isfinite(verts[i])) {
            set_error("cfc_repair_surface: a vertex is not finite");
            return -1;
        }
    for (int i = 0; i < 3 * nt; i++)
        if (tris[i] < 0 || tris[i] >= nv) {
            set_error("cfc_repair_surface: a triangle's corner is out of range");
            return -1;
        }
    try {
        return repair(verts, nv, tris, nt, v_out, nv_out, tri_out, nt_out, rep);
    } catch (const std::bad_alloc &) {
        set_error("out of memory in CGAL's surface repair");
    } catch (const std::exception &e) {
        std::snprintf(g_error, sizeof g_error, "CGAL's surface repair refused the surface: %s",
                      e.what());
        for (char *c = g_error; *c; c++) /* CGAL's messages span lines; ours are one */
            if (*c == '\n')
                *c = ' ';
    } catch (...) {
        set_error("CGAL's surface repair failed");
    }
    return -1;
}

int cfc_wrap_surface(const double *verts, int nv, const int *tris, int nt, double alpha,
                     double offset, double **v_out, int *nv_out, int **tri_out, int *nt_out)
{
    if (!verts || !tris || !v_out || !nv_out || !tri_out || !nt_out || nv < 3 || nt < 1 ||
        !(alpha > 0) || !(offset > 0) || !std::isfinite(alpha) || !std::isfinite(offset)) {
        set_error("cfc_wrap_surface: no surface, or alpha or offset not positive");
        return -1;
    }
    try {
        std::vector<Ki::Point_3> p;
        std::vector<std::array<std::size_t, 3>> f;
        triangle_soup(verts, nv, tris, nt, p, f);
        Mesh_inexact w;
        CGAL::alpha_wrap_3(p, f, alpha, offset, w);
        return copy_out(w, v_out, nv_out, tri_out, nt_out);
    } catch (const std::bad_alloc &) {
        set_error("out of memory in CGAL's alpha wrapping");
    } catch (...) {
        set_error("CGAL's alpha wrapping failed");
    }
    return -1;
}

int cfc_remesh_surface(const double *verts, int nv, const int *tris, int nt, double edge,
                       double **v_out, int *nv_out, int **tri_out, int *nt_out)
{
    if (!verts || !tris || !v_out || !nv_out || !tri_out || !nt_out || nv < 3 || nt < 1 ||
        !(edge > 0) || !std::isfinite(edge)) {
        set_error("cfc_remesh_surface: no surface, or an edge length that is not positive");
        return -1;
    }
    try {
        std::vector<Ki::Point_3> p;
        std::vector<std::array<std::size_t, 3>> f;
        triangle_soup(verts, nv, tris, nt, p, f);
        Mesh_inexact m;
        if (!CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(f)) {
            set_error("cfc_remesh_surface: the surface is not a manifold mesh");
            return -1;
        }
        CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(p, f, m);
        CGAL::Polygon_mesh_processing::isotropic_remeshing(
            faces(m), edge, m,
            CGAL::parameters::number_of_iterations(CFC_REMESH_ITERATIONS));
        m.collect_garbage();
        return copy_out(m, v_out, nv_out, tri_out, nt_out);
    } catch (const std::bad_alloc &) {
        set_error("out of memory in CGAL's isotropic remeshing");
    } catch (...) {
        set_error("CGAL's isotropic remeshing failed");
    }
    return -1;
}

const char *cfc_last_error(void) { return g_error; }

}  // extern "C"
