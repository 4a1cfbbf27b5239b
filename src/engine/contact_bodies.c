/* Contact between fracture-mode fragments of different bodies: node to
 * deforming surface, a PBD contact constraint (see contact.h). */
#include "contact.h"

#include "cf_fcl.h"
#include "grow.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cf_frag_surface_free(cf_frag_surface *fs)
{
    cff_mesh_destroy(fs->mesh);
    free(fs->node), free(fs->slot), free(fs->tri), free(fs->xv);
    memset(fs, 0, sizeof *fs);
}

/* The contact caches: a table keyed by fragment (contact.h). */
int cf_contact_caches_reserve(cf_contact_caches *c, int n)
{
    int held = c->cap;
    if (cf_grow_to((void **)&c->v, &c->cap, n, sizeof *c->v, 16))
        return -1;
    memset(&c->v[held], 0, (size_t)(c->cap - held) * sizeof *c->v);
    return 0;
}

void cf_contact_cache_clear(cf_contact_caches *c, int fi)
{
    if (fi >= c->cap)
        return;
    cf_node_impulses_free(&c->v[fi].push);
    cf_hull_set_free(&c->v[fi].near);
    cf_frag_surface_free(&c->v[fi].surface);
}

void cf_contact_caches_free(cf_contact_caches *c)
{
    for (int fi = 0; fi < c->cap; fi++)
        cf_contact_cache_clear(c, fi);
    free(c->v);
    c->v = NULL, c->cap = 0;
}

/* The faces of f's tets that no other of its tets uses, on the current
 * nodes, built over the rest positions (a valid mesh whatever the
 * deformation) and refitted later.  Returns 0, or -1. */
static int surface_build(const cf_solid *s, const cf_fragment *f, cf_frag_surface *fs)
{
    cf_frag_surface_free(fs);
    int rc = -1, nf = 4 * f->nt;
    int *local = malloc((size_t)s->n_nodes * sizeof(int));
    double *rest = NULL;
    size_t room = (size_t)(nf > 0 ? nf : 1) * 3; /* corners of every tet face */
    fs->tri = malloc(room * sizeof(int));
    fs->node = malloc(room * sizeof(int));
    fs->slot = malloc(room * sizeof(int));
    if (!local || !fs->tri || !fs->node || !fs->slot ||
        (fs->ntri = cf_boundary_faces(s->tet, f->tets, f->nt, fs->tri)) < 0)
        goto done;
    for (int a = 0; a < s->n_nodes; a++)
        local[a] = -1;
    for (int i = 0; i < 3 * fs->ntri; i++) { /* nodes -> surface vertices */
        int a = fs->tri[i];
        if (local[a] < 0)
            local[a] = fs->nv, fs->node[fs->nv++] = a;
        fs->tri[i] = local[a];
    }
    fs->xv = malloc((size_t)(fs->nv > 0 ? fs->nv : 1) * 3 * sizeof(double));
    rest = malloc((size_t)(fs->nv > 0 ? fs->nv : 1) * 3 * sizeof(double));
    if (!fs->xv || !rest)
        goto done;
    for (int i = 0; i < fs->nv; i++)
        memcpy(&rest[3 * i], &s->X[3 * fs->node[i]], 3 * sizeof(double));
    for (int i = 0; i < f->nodes.n; i++) /* local now maps node -> surface vertex */
        if (local[f->nodes.v[i]] >= 0)
            fs->slot[local[f->nodes.v[i]]] = i;
    fs->mesh = cff_mesh_create_deforming(rest, fs->nv, fs->tri, fs->ntri);
    fs->built_nodes = f->nodes.n;
    rc = fs->mesh ? 0 : -1;
done:
    free(local), free(rest);
    if (rc)
        cf_frag_surface_free(fs);
    return rc;
}

/* The surface of f at the nodes' current positions (built when missing or
 * when node duplication has changed it).  Returns 0, 1 when a position is
 * not finite (a diverged fragment: the engine's guard reports it), or -1. */
static int surface_refit(const cf_solid *s, const cf_fragment *f, cf_frag_surface *fs)
{
    if ((!fs->mesh || fs->built_nodes != f->nodes.n) && surface_build(s, f, fs))
        return -1;
    for (int i = 0; i < fs->nv; i++) {
        const double *x = &s->x[3 * fs->node[i]];
        if (!isfinite(x[0] + x[1] + x[2]))
            return 1;
        memcpy(&fs->xv[3 * i], x, 3 * sizeof(double));
    }
    return cff_mesh_update(fs->mesh, fs->xv);
}

/* Bounding box of f's nodes: box[0..2] lo, box[3..5] hi, m. */
static void node_box(const cf_solid *s, const cf_fragment *f, double box[6])
{
    for (int k = 0; k < 3; k++)
        box[k] = INFINITY, box[3 + k] = -INFINITY;
    for (int i = 0; i < f->nodes.n; i++)
        for (int k = 0; k < 3; k++) {
            double x = s->x[3 * f->nodes.v[i] + k];
            box[k] = fmin(box[k], x), box[3 + k] = fmax(box[3 + k], x);
        }
}

/* A node a contact pass moved, for the pass's work. */
typedef struct moved_node {
    int node;
    double v0[3];   /* velocity before the pass, m/s */
    double vh[3];   /* velocity at the start of the step, m/s */
} moved_node;

typedef struct moved_nodes {
    int n, cap;
    int *slot;      /* [n_nodes] record of each node, -1 */
    moved_node *m;  /* [cap] */
} moved_nodes;

static void moved_free(moved_nodes *mv)
{
    free(mv->slot), free(mv->m);
}

/* Record node a (fragment f, local index i) before its first move.
 * Returns 0, or -1 out of memory. */
static int remember(moved_nodes *mv, const cf_solid *s, const cf_fragment *f, int i, int a)
{
    if (!mv->slot) {
        mv->slot = malloc((size_t)s->n_nodes * sizeof(int));
        if (!mv->slot)
            return -1;
        for (int k = 0; k < s->n_nodes; k++)
            mv->slot[k] = -1;
    }
    if (mv->slot[a] >= 0)
        return 0;
    if (mv->n == mv->cap) {
        int cap = 2 * mv->cap + 64;
        moved_node *m = realloc(mv->m, (size_t)cap * sizeof *m);
        if (!m)
            return -1;
        mv->m = m, mv->cap = cap;
    }
    moved_node *r = &mv->m[mv->n];
    mv->slot[a] = mv->n++;
    r->node = a;
    memcpy(r->v0, &s->v[3 * a], sizeof r->v0);
    memcpy(r->vh, &f->v_old[3 * i], sizeof r->vh);
    return 0;
}

/* Work of the pass's impulses, J: for each moved node the leapfrog work
 * of a force at this step, m (v - v0) . (v_start + v)/2 with v_start the
 * velocity at the start of the step (as the boundary's work is booked), so
 * that the energy ledger balances. */
static double moved_work(const moved_nodes *mv, const cf_solid *s)
{
    double w = 0;
    for (int k = 0; k < mv->n; k++) {
        const moved_node *r = &mv->m[k];
        const double *v = &s->v[3 * r->node];
        for (int c = 0; c < 3; c++)
            w += s->m[r->node] * (v[c] - r->v0[c]) * 0.5 * (r->vh[c] + v[c]);
    }
    return w;
}

static double inverse_mass(const cf_solid *s, int a)
{
    return s->bc[a] >= 0 || !(s->m[a] > 0) ? 0 : 1 / s->m[a];
}

/* Move node a (fragment f, local index i) by `amount` times u and change
 * its velocity by that over h.  Returns 0, or -1 out of memory. */
static int move(cf_solid *s, moved_nodes *mv, const cf_fragment *f, int i, int a, double amount,
                const double u[3], double h)
{
    if (amount == 0)
        return 0;
    if (remember(mv, s, f, i, a))
        return -1;
    v3_axpy(amount, u, &s->x[3 * a]);
    v3_axpy(amount / h, u, &s->v[3 * a]);
    return 0;
}

/* Every node of fragment fa inside box_b and behind fb's surface, projected
 * out with it (the constraint of contact.h).  Returns 0, or -1. */
static int push_out(const cf_contact_ctx *ctx, const cf_fragment *fa, const cf_fragment *fb,
                    cf_frag_surface *sb, const double box_b[6], double h, moved_nodes *mv)
{
    cf_solid *s = ctx->solid;
    int fit = surface_refit(s, fb, sb);
    if (fit)
        return fit < 0 ? -1 : 0;
    for (int i = 0; i < fa->nodes.n; i++) {
        int a = fa->nodes.v[i];
        const double *xa = &s->x[3 * a];
        if (!cf_boxes_overlap(xa, xa, box_b, box_b + 3)) /* also skips a non-finite node */
            continue;
        double q[3], n[3], d, l[3], u[3];
        int tri, found = cff_mesh_closest_tri(sb->mesh, xa, INFINITY, q, n, &d, &tri, l);
        if (found < 0)
            return -1;
        if (!found || !(d < 0))
            continue;
        v3_sub(q, xa, u); /* |u| = -d */
        double wa = inverse_mass(s, a), W = wa, w[3];
        int b[3];
        for (int k = 0; k < 3; k++) {
            b[k] = sb->node[sb->tri[3 * tri + k]];
            w[k] = inverse_mass(s, b[k]);
            W += l[k] * l[k] * w[k];
        }
        if (!(W > 0))
            continue;
        if (move(s, mv, fa, i, a, wa / W, u, h))
            return -1;
        for (int k = 0; k < 3; k++) {
            int v = sb->tri[3 * tri + k];
            if (move(s, mv, fb, sb->slot[v], b[k], -l[k] * w[k] / W, u, h))
                return -1;
        }
    }
    return 0;
}

int cf_body_contact_needed(const cf_contact_ctx *ctx)
{
    int first_root = -1;
    for (int fi = 0; fi < ctx->n_frag; fi++) {
        if (ctx->frag[fi].mode != CF_MODE_FRACTURE)
            continue;
        int r = cf_fragment_root(ctx->frag, fi);
        if (first_root >= 0 && r != first_root)
            return 1;
        first_root = r;
    }
    return 0;
}

int cf_body_contact(const cf_contact_ctx *ctx, double h, double *removed)
{
    *removed = 0;
    int n = ctx->n_frag;
    size_t mark = cf_arena_mark(ctx->arena);
    double *box = cf_arena_take(ctx->arena, (size_t)n * 6 * sizeof(double));
    int *root = cf_arena_take(ctx->arena, (size_t)n * sizeof(int));
    if (!box || !root) {
        cf_arena_release(ctx->arena, mark);
        return -1;
    }
    for (int fi = 0; fi < n; fi++)
        if (ctx->frag[fi].mode == CF_MODE_FRACTURE) {
            node_box(ctx->solid, &ctx->frag[fi], &box[6 * fi]);
            root[fi] = cf_fragment_root(ctx->frag, fi);
        }
    int rc = 0;
    moved_nodes mv = {0};
    for (int i = 0; i < n && !rc; i++) {
        cf_fragment *fa = &ctx->frag[i];
        if (fa->mode != CF_MODE_FRACTURE)
            continue;
        for (int j = i + 1; j < n && !rc; j++) {
            cf_fragment *fb = &ctx->frag[j];
            if (fb->mode != CF_MODE_FRACTURE || root[j] == root[i] ||
                !cf_boxes_overlap(&box[6 * i], &box[6 * i + 3], &box[6 * j], &box[6 * j + 3]))
                continue;
            rc = push_out(ctx, fa, fb, &ctx->cache[j].surface, &box[6 * j], h, &mv) ||
                 push_out(ctx, fb, fa, &ctx->cache[i].surface, &box[6 * i], h, &mv);
        }
    }
    *removed = -moved_work(&mv, ctx->solid);
    moved_free(&mv);
    cf_arena_release(ctx->arena, mark);
    return rc ? -1 : 0;
}
