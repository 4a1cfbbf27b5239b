/* cohfrac-repair — the surface repair of `cohfrac mesh`, as a program of
 * its own: CGAL's Polygon Mesh Processing and 3D Alpha Wrapping
 * (bullet_bridge/cf_cgal.h) are GPL-3.0-or-later, so they are run, as
 * tetgen is, rather than linked into the BSD-licensed library (NOTICE).
 *
 *   cohfrac-repair repair IN OUT
 *   cohfrac-repair wrap ALPHA OFFSET IN OUT
 *   cohfrac-repair remesh EDGE IN OUT
 *
 * IN and OUT are surface hand-over files (src/mesh/surface_raw.h: doubles,
 * so nothing is rounded on the way).  On success writes OUT and, for
 * `repair`, one line "report K=V ..." on stdout (the fields of
 * cfc_repair_report), exit 0; on failure one line "error: ..." on stderr,
 * exit 1 (2 for a bad command line). */
#include "cf_cgal.h"
#include "surface_raw.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(const char *what)
{
    fprintf(stderr, "error: %s\n", what);
    return 1;
}

int main(int argc, char **argv)
{
    int repair = argc == 4 && strcmp(argv[1], "repair") == 0;
    int wrap = argc == 6 && strcmp(argv[1], "wrap") == 0;
    int remesh = argc == 5 && strcmp(argv[1], "remesh") == 0;
    if (!repair && !wrap && !remesh) {
        fprintf(stderr, "usage: cohfrac-repair repair IN OUT\n"
                        "       cohfrac-repair wrap ALPHA OFFSET IN OUT\n"
                        "       cohfrac-repair remesh EDGE IN OUT\n");
        return 2;
    }
    const char *in = argv[argc - 2], *out = argv[argc - 1];
    cf_surface s = {0};
    cf_error err = {0};
    if (cf_surface_read_raw(in, &s, &err) != CF_OK)
        return fail(err.msg);
    double *v;
    int *tri, nv, nt, rc;
    cfc_repair_report r = {0};
    if (repair) {
        rc = cfc_repair_surface(s.v, s.n_verts, s.tri, s.n_tris, &v, &nv, &tri, &nt, &r);
    } else if (remesh) {
        char *e;
        double edge = strtod(argv[2], &e);
        if (*e || !(edge > 0)) {
            fprintf(stderr, "error: EDGE must be a number > 0\n");
            return 2;
        }
        rc = cfc_remesh_surface(s.v, s.n_verts, s.tri, s.n_tris, edge, &v, &nv, &tri, &nt);
    } else {
        char *e1, *e2;
        double alpha = strtod(argv[2], &e1), offset = strtod(argv[3], &e2);
        if (*e1 || *e2 || !(alpha > 0) || !(offset > 0)) {
            fprintf(stderr, "error: ALPHA and OFFSET must be numbers > 0\n");
            return 2;
        }
        rc = cfc_wrap_surface(s.v, s.n_verts, s.tri, s.n_tris, alpha, offset, &v, &nv, &tri, &nt);
    }
    free(s.v), free(s.tri);
    if (rc != 0)
        return fail(cfc_last_error());
    cf_surface o = {nv, nt, v, tri};
    cf_status st = cf_surface_write_raw(&o, out, &err);
    free(v), free(tri);
    if (st != CF_OK)
        return fail(err.msg);
    if (repair)
        printf("report points_merged=%d faces_removed=%d faces_reoriented=%d holes_filled=%d "
               "intersecting_pairs=%d intersections_fixed=%d wrap_alpha=%.17g "
               "wrap_offset=%.17g faces_in=%d faces_out=%d\n",
               r.points_merged, r.faces_removed, r.faces_reoriented, r.holes_filled,
               r.intersecting_pairs, r.intersections_fixed, r.wrap_alpha, r.wrap_offset,
               r.faces_in, r.faces_out);
    return 0;
}
