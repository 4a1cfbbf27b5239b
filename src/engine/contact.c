/* Fracture-mode nodes against the convex hulls of rigid fragments. */
#include "contact.h"

#include "linalg.h"

#include <ccd/ccd.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The two objects of a query: a point, and hull h of a set. */
typedef struct hull_ref {
    const cf_hull_set *hs;
    int h;
} hull_ref;

static void support_point(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    (void)dir;
    const double *p = obj;
    ccdVec3Set(out, p[0], p[1], p[2]);
}

static void center_point(const void *obj, ccd_vec3_t *out)
{
    const double *p = obj;
    ccdVec3Set(out, p[0], p[1], p[2]);
}

static void support_hull(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const hull_ref *r = obj;
    const cf_hull_set *hs = r->hs;
    const double d[3] = {ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir)};
    int best = hs->start[r->h];
    double best_dot = -INFINITY;
    for (int i = hs->start[r->h]; i < hs->start[r->h + 1]; i++) {
        double s = v3_dot(&hs->pts[3 * i], d);
        if (s > best_dot)
            best_dot = s, best = i;
    }
    ccdVec3Set(out, hs->pts[3 * best], hs->pts[3 * best + 1], hs->pts[3 * best + 2]);
}

static void center_hull(const void *obj, ccd_vec3_t *out)
{
    const hull_ref *r = obj;
    const double *c = &r->hs->center[3 * r->h];
    ccdVec3Set(out, c[0], c[1], c[2]);
}

int cf_boxes_overlap(const double lo0[3], const double hi0[3], const double lo1[3],
                     const double hi1[3])
{
    for (int k = 0; k < 3; k++)
        if (lo0[k] > hi1[k] || lo1[k] > hi0[k])
            return 0;
    return 1;
}

/* Append body fragment g's hulls in world coordinates. */
static int add_hulls(const cf_contact_ctx *ctx, int g, cf_hull_set *hs)
{
    const cf_fragment *f = &ctx->frag[g];
    const cf_hulls *h = &f->hulls;
    cfb_state st;
    double R[9];
    cfb_get_state(ctx->bullet, f->body, &st);
    quat_to_mat(st.quat, R);
    int nv0 = hs->start[hs->n], nv = h->start[h->n_hulls], n = hs->n + h->n_hulls;
    double *pts = realloc(hs->pts, (size_t)(nv0 + nv) * 3 * sizeof(double));
    if (pts)
        hs->pts = pts;
    int *start = realloc(hs->start, (size_t)(n + 1) * sizeof(int));
    if (start)
        hs->start = start;
    int *frag = realloc(hs->frag, (size_t)n * sizeof(int));
    if (frag)
        hs->frag = frag;
    double *bx[3] = {realloc(hs->lo, (size_t)n * 3 * sizeof(double)), NULL, NULL};
    if (bx[0])
        hs->lo = bx[0];
    bx[1] = realloc(hs->hi, (size_t)n * 3 * sizeof(double));
    if (bx[1])
        hs->hi = bx[1];
    bx[2] = realloc(hs->center, (size_t)n * 3 * sizeof(double));
    if (bx[2])
        hs->center = bx[2];
    if (!pts || !start || !frag || !bx[0] || !bx[1] || !bx[2])
        return -1;
    for (int k = 0; k < h->n_hulls; k++) {
        int c = hs->n + k;
        double *lo = &hs->lo[3 * c], *hi = &hs->hi[3 * c], *cen = &hs->center[3 * c];
        for (int d = 0; d < 3; d++)
            lo[d] = INFINITY, hi[d] = -INFINITY, cen[d] = 0;
        int m = h->start[k + 1] - h->start[k];
        for (int i = h->start[k]; i < h->start[k + 1]; i++) {
            double *x = &hs->pts[3 * (nv0 + i)];
            m3_mulv(R, &h->pts[3 * i], x);
            for (int d = 0; d < 3; d++) {
                x[d] += st.pos[d];
                lo[d] = fmin(lo[d], x[d]);
                hi[d] = fmax(hi[d], x[d]);
                cen[d] += x[d] / m;
            }
        }
        hs->start[c + 1] = nv0 + h->start[k + 1];
        hs->frag[c] = g;
    }
    hs->n = n;
    return 0;
}

void cf_body_boxes(const cf_contact_ctx *ctx, double *b)
{
    for (int g = 0; g < ctx->n_frag; g++) {
        const cf_fragment *o = &ctx->frag[g];
        double *lo = &b[6 * g], *hi = lo + 3;
        if (!ctx->bullet || o->mode != CF_MODE_RIGID || o->body < 0 ||
            cfb_get_aabb(ctx->bullet, o->body, lo, hi))
            for (int d = 0; d < 3; d++)
                lo[d] = INFINITY, hi[d] = -INFINITY; /* overlaps nothing */
    }
}

int cf_hull_set_gather(const cf_contact_ctx *ctx, int fi, double pad, const double *boxes,
                       cf_hull_set *hs)
{
    const cf_fragment *f = &ctx->frag[fi];
    const cf_solid *s = ctx->solid;
    hs->n = 0;
    if (!hs->start && !(hs->start = calloc(1, sizeof(int))))
        return -1;
    hs->start[0] = 0;
    if (!ctx->bullet)
        return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < f->nodes.n; i++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], s->x[3 * f->nodes.v[i] + d] - pad);
            hi[d] = fmax(hi[d], s->x[3 * f->nodes.v[i] + d] + pad);
        }
    double size = 0;
    int root = cf_fragment_root(ctx->frag, fi);
    for (int g = 0; g < ctx->n_frag; g++) {
        const cf_fragment *o = &ctx->frag[g];
        /* Fragments of one body do not collide (as in Bullet, §9): their
         * hulls overlap where a crack face is not convex, and a hull that
         * pushes a sibling's node pushes it into whatever holds it (the
         * ground's penalty then springs it back with energy no load put
         * in).  Debris has no hulls: a sphere in Bullet, too small to hold
         * a node (§9.2). */
        if (cf_fragment_root(ctx->frag, g) == root || o->hulls.n_hulls == 0 ||
            !cf_boxes_overlap(lo, hi, &boxes[6 * g], &boxes[6 * g + 3]))
            continue;
        if (add_hulls(ctx, g, hs))
            return -1;
        size = fmax(size, cbrt(o->mass / s->mat.rho));
    }
    hs->tolerance = 1e-4 * size;
    return 0;
}

void cf_hull_set_free(cf_hull_set *hs)
{
    free(hs->pts), free(hs->start), free(hs->lo), free(hs->hi), free(hs->center), free(hs->frag);
    memset(hs, 0, sizeof *hs);
}

/* Penetration of point p into hull h by Minkowski portal refinement: the
 * depth (m) below, and the normal (unit) of, the hull face that the ray
 * from the hull's centroid through p leaves by; dir is the way the hull
 * would move to part.  GJK + EPA degenerates for a point (a zero-volume
 * Minkowski simplex); for a node that crossed the surface in one step the
 * portal face is the face it crossed.  Returns 1 when inside. */
static int penetration(const cf_hull_set *hs, int h, const double p[3], double *depth,
                       double dir[3])
{
    if (!cf_boxes_overlap(p, p, &hs->lo[3 * h], &hs->hi[3 * h]))
        return 0;
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = support_point;
    ccd.support2 = support_hull;
    ccd.center1 = center_point;
    ccd.center2 = center_hull;
    ccd.max_iterations = 100;
    ccd.mpr_tolerance = hs->tolerance;
    hull_ref ref = {hs, h};
    ccd_real_t d;
    ccd_vec3_t v, pos;
    if (ccdMPRPenetration(p, &ref, &ccd, &d, &v, &pos) != 0 || !(d > 0))
        return 0;
    *depth = d;
    dir[0] = ccdVec3X(&v), dir[1] = ccdVec3Y(&v), dir[2] = ccdVec3Z(&v);
    return 1;
}

int cf_hull_set_project(const cf_hull_set *hs, const double x[3], double p[3])
{
    int hit = -1;
    for (int h = 0; h < hs->n; h++) {
        double depth, dir[3], d2, dir2[3];
        if (!penetration(hs, h, p, &depth, dir) || penetration(hs, h, x, &d2, dir2))
            continue;
        /* The point moves against the hull's parting direction. */
        v3_axpy(-depth, dir, p);
        hit = h;
    }
    return hit;
}

int cf_node_impulses_reserve(cf_node_impulses *ni, int n)
{
    if (n <= ni->n)
        return 0;
    int *frag = realloc(ni->frag, (size_t)n * sizeof(int));
    if (frag)
        ni->frag = frag;
    double *J = realloc(ni->J, (size_t)n * 3 * sizeof(double));
    if (J)
        ni->J = J;
    double *pt = realloc(ni->point, (size_t)n * 3 * sizeof(double));
    if (pt)
        ni->point = pt;
    if (!frag || !J || !pt)
        return -1;
    for (int i = ni->n; i < n; i++)
        ni->frag[i] = -1;
    memset(&ni->J[3 * ni->n], 0, (size_t)(n - ni->n) * 3 * sizeof(double));
    ni->n = n;
    return 0;
}

void cf_node_impulses_add(cf_node_impulses *ni, int i, int frag, const double dJ[3],
                          const double point[3])
{
    ni->frag[i] = frag;
    v3_axpy(1.0, dJ, &ni->J[3 * i]);
    memcpy(&ni->point[3 * i], point, 3 * sizeof(double));
}

void cf_node_impulses_free(cf_node_impulses *ni)
{
    free(ni->frag), free(ni->J), free(ni->point);
    memset(ni, 0, sizeof *ni);
}

/* Per body pushed in this rigid step: the impulses' sum, the fastest node
 * that pushed it, the scale of its impulses and its spin before them. */
typedef struct {
    double J[3], vmax, beta, w0[3];
    int hit;
} push_sum;

int cf_node_impulses_flush(const cf_contact_ctx *ctx, cf_node_impulses *ni, const int *nodes,
                           double *energy)
{
    int n = ctx->n_frag, pushed = 0;
    /* Most fragments pushed nothing: without this test each paid for a sum
     * per fragment of the world (a shattering bar's thousands of pieces,
     * thousands squared). */
    for (int i = 0; i < ni->n && !pushed; i++)
        pushed = ni->frag[i] >= 0;
    *energy = 0;
    if (!pushed)
        return 0;
    /* Without the sums the pushes could not be bounded: an error, not
     * unbounded impulses. */
    size_t mark = cf_arena_mark(ctx->arena);
    push_sum *sum = cf_arena_take(ctx->arena, ((size_t)n + 1) * sizeof *sum);
    if (!sum)
        return -1;
    memset(sum, 0, ((size_t)n + 1) * sizeof *sum);
    double gained = 0, bounce = 1.0 + ctx->solid->mat.restitution;
    for (int i = 0; i < ni->n; i++) {
        int g = ni->frag[i];
        if (g < 0 || ctx->frag[g].body < 0)
            continue;
        v3_axpy(-1.0, &ni->J[3 * i], sum[g].J);
        sum[g].vmax = fmax(sum[g].vmax, v3_norm(&ctx->solid->v[3 * nodes[i]]));
        sum[g].hit = 1;
    }
    for (int g = 0; g < n; g++) {
        if (!sum[g].hit)
            continue;
        cfb_state st;
        cfb_get_state(ctx->bullet, ctx->frag[g].body, &st);
        memcpy(sum[g].w0, st.w, sizeof st.w);
        double Jl = v3_norm(sum[g].J), dv = Jl / ctx->frag[g].mass;
        double room = Jl > 0 ? bounce * sum[g].vmax - v3_dot(st.v, sum[g].J) / Jl : dv;
        sum[g].beta = dv > room ? fmax(0.0, room) / dv : 1.0;
        gained -= cf_body_kinetic_energy(&ctx->frag[g], &st);
    }
    for (int i = 0; i < ni->n; i++) {
        int g = ni->frag[i];
        if (g < 0)
            continue;
        cf_fragment *o = &ctx->frag[g];
        double beta = sum[g].beta;
        double J[3] = {-beta * ni->J[3 * i], -beta * ni->J[3 * i + 1], -beta * ni->J[3 * i + 2]};
        if (o->body >= 0) {
            cfb_apply_impulse(ctx->bullet, o->body, J, &ni->point[3 * i]);
            o->pushed += v3_norm(J);
        }
        if (beta < 1.0) { /* what the body did not take stays with the node */
            int a = nodes[i];
            double *va = &ctx->solid->v[3 * a], m = ctx->solid->m[a];
            gained -= 0.5 * m * v3_dot(va, va);
            v3_axpy(-(1.0 - beta) / m, &ni->J[3 * i], va);
            gained += 0.5 * m * v3_dot(va, va);
        }
        ni->frag[i] = -1;
        memset(&ni->J[3 * i], 0, 3 * sizeof(double));
    }
    for (int g = 0; g < n; g++) { /* the spin the pushes gave, bounded likewise */
        if (!sum[g].hit)
            continue;
        const cf_fragment *o = &ctx->frag[g];
        cfb_state st;
        cfb_get_state(ctx->bullet, o->body, &st);
        double dw[3], Rb[9], wb[3], e = 0, v2 = bounce * sum[g].vmax;
        v3_sub(st.w, sum[g].w0, dw);
        quat_to_mat(st.quat, Rb);
        m3_tmulv(Rb, dw, wb);
        for (int k = 0; k < 3; k++)
            e += 0.5 * o->principal[k] * wb[k] * wb[k];
        double limit = 0.5 * o->mass * v2 * v2;
        if (e > limit) {
            double gamma = sqrt(limit / e);
            for (int k = 0; k < 3; k++)
                st.w[k] = sum[g].w0[k] + gamma * dw[k];
            cfb_set_state(ctx->bullet, o->body, &st);
        }
        cfb_get_state(ctx->bullet, o->body, &st); /* as Bullet holds it */
        gained += cf_body_kinetic_energy(o, &st);
    }
    cf_arena_release(ctx->arena, mark);
    *energy = gained;
    return 0;
}
