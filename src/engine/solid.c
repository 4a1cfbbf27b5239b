#include "solid.h"

#include "linalg.h"
#include "sort.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

const int CF_TET_FACE[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

typedef struct {
    int v[3];
    int tet, face;
} face_key;

static int cmp_face(const void *a, const void *b)
{
    const face_key *x = a, *y = b;
    for (int i = 0; i < 3; i++)
        if (x->v[i] != y->v[i])
            return x->v[i] < y->v[i] ? -1 : 1;
    return x->tet != y->tet ? (x->tet < y->tet ? -1 : 1) : 0;
}

static void sort3(int v[3])
{
    int t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

void cf_solid_update_open(cf_solid *s, int f)
{
    const int *F = &s->facet[4 * f];
    unsigned char bit = (unsigned char)(1u << F[1]);
    if (F[2] >= 0 && !s->cracked[f] && (!s->candidate || s->candidate[f]))
        s->tet_open[F[0]] |= bit;
    else
        s->tet_open[F[0]] &= (unsigned char)~bit;
}

/* Facets by sorting the 4 faces of every tet on their vertex triple. */
static int build_facets(cf_solid *s)
{
    int nt = s->n_tets, nfk = 4 * nt;
    face_key *k = malloc((size_t)nfk * sizeof *k);
    s->facet = malloc((size_t)nfk * 4 * sizeof(int));
    s->tet_facet = malloc((size_t)nfk * sizeof(int));
    if (!k || !s->facet || !s->tet_facet) {
        free(k);
        return -1;
    }
    for (int t = 0; t < nt; t++)
        for (int f = 0; f < 4; f++) {
            face_key *e = &k[4 * t + f];
            for (int i = 0; i < 3; i++)
                e->v[i] = s->tet0[4 * t + CF_TET_FACE[f][i]];
            sort3(e->v);
            e->tet = t, e->face = f;
        }
    qsort(k, (size_t)nfk, sizeof *k, cmp_face);
    int nf = 0;
    for (int i = 0; i < nfk;) {
        int *F = &s->facet[4 * nf];
        F[0] = k[i].tet, F[1] = k[i].face, F[2] = -1, F[3] = -1;
        s->tet_facet[4 * k[i].tet + k[i].face] = nf;
        if (i + 1 < nfk && !memcmp(k[i].v, k[i + 1].v, sizeof k[i].v)) {
            F[2] = k[i + 1].tet, F[3] = k[i + 1].face;
            s->tet_facet[4 * k[i + 1].tet + k[i + 1].face] = nf;
            i += 2;
        } else {
            i += 1;
        }
        nf++;
    }
    free(k);
    s->n_facets = nf;
    s->cracked = calloc((size_t)nf, 1);
    s->tet_open = calloc((size_t)(s->n_tets > 0 ? s->n_tets : 1), 1);
    for (int f = 0; s->cracked && s->tet_open && f < nf; f++)
        cf_solid_update_open(s, f);
    s->edge_cracks = calloc((size_t)(s->n_tets > 0 ? s->n_tets : 1), 6);
    s->crack_time = calloc((size_t)(nf > 0 ? nf : 1), sizeof(double));
    s->contact_key = calloc((size_t)(nf > 0 ? nf : 1), sizeof(uint64_t));
    s->contact_kind = calloc((size_t)(nf > 0 ? nf : 1), 1);
    s->contact_until = calloc((size_t)(nf > 0 ? nf : 1), sizeof(double));
    return s->cracked && s->tet_open && s->edge_cracks && s->crack_time && s->contact_key &&
                   s->contact_kind && s->contact_until
               ? 0
               : -1;
}

int cf_boundary_faces(const int *tet_nodes, const int *list, int nt, int *faces)
{
    int nfk = 4 * nt, n = 0;
    face_key *k = malloc((size_t)(nfk > 0 ? nfk : 1) * sizeof *k);
    if (!k)
        return -1;
    for (int i = 0; i < nt; i++) {
        int t = list ? list[i] : i;
        for (int f = 0; f < 4; f++) {
            face_key *e = &k[4 * i + f];
            for (int j = 0; j < 3; j++)
                e->v[j] = tet_nodes[4 * t + CF_TET_FACE[f][j]];
            sort3(e->v);
            e->tet = t, e->face = f;
        }
    }
    qsort(k, (size_t)nfk, sizeof *k, cmp_face);
    for (int i = 0; i < nfk;) {
        int j = i + 1;
        while (j < nfk && !memcmp(k[i].v, k[j].v, sizeof k[i].v))
            j++;
        if (j == i + 1) {
            for (int c = 0; c < 3; c++)
                faces[3 * n + c] = tet_nodes[4 * k[i].tet + CF_TET_FACE[k[i].face][c]];
            n++;
        }
        i = j;
    }
    free(k);
    return n;
}

static int build_vertex_tets(cf_solid *s)
{
    int nv = s->n_verts0, nt = s->n_tets;
    s->vt_start = calloc((size_t)nv + 1, sizeof(int));
    s->vt_slot = malloc((size_t)nt * 4 * sizeof(int));
    s->vert_cracks = calloc((size_t)nv + 1, sizeof(unsigned));
    if (!s->vt_start || !s->vt_slot || !s->vert_cracks)
        return -1;
    for (int i = 0; i < 4 * nt; i++)
        s->vt_start[s->tet0[i] + 1]++;
    for (int v = 0; v < nv; v++)
        s->vt_start[v + 1] += s->vt_start[v];
    int *fill = malloc((size_t)nv * sizeof(int));
    if (!fill)
        return -1;
    memcpy(fill, s->vt_start, (size_t)nv * sizeof(int));
    for (int t = 0; t < nt; t++) /* ascending tet order within each list */
        for (int j = 0; j < 4; j++)
            s->vt_slot[fill[s->tet0[4 * t + j]]++] = 4 * t + j;
    free(fill);
    return 0;
}

static double tri_area(const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], n[3];
    v3_sub(b, a, e1), v3_sub(c, a, e2), v3_cross(e1, e2, n);
    return 0.5 * v3_norm(n);
}

/* Dilatational wave speed c_d, m/s (docs/physics.md §3). */
static double wave_speed(const cf_material *mat)
{
    return sqrt(mat->E * (1 - mat->nu) / (mat->rho * (1 + mat->nu) * (1 - 2 * mat->nu)));
}

/* Dm = [x1 - x0, x2 - x0, x3 - x0] (columns), row-major. */
static void edge_matrix(const double *x0, const double *x1, const double *x2, const double *x3,
                        double Dm[9])
{
    for (int r = 0; r < 3; r++)
        Dm[3 * r] = x1[r] - x0[r], Dm[3 * r + 1] = x2[r] - x0[r], Dm[3 * r + 2] = x3[r] - x0[r];
}

/* Twice the inradius of a tet of volume `vol`: 6 V / (total face area). */
static double tet_h(double vol, const double *x0, const double *x1, const double *x2,
                    const double *x3)
{
    double area = tri_area(x1, x2, x3) + tri_area(x0, x3, x2) + tri_area(x0, x1, x3) +
                  tri_area(x0, x2, x1);
    return 6.0 * vol / area;
}

double cf_mesh_dt_cfl(const cf_mesh *m, double scale, const cf_material *mat)
{
    double c_d = wave_speed(mat), dt = INFINITY;
    for (int t = 0; t < m->n_tets; t++) {
        const int *T = &m->tets[4 * t];
        const double *x0 = &m->x[3 * T[0]], *x1 = &m->x[3 * T[1]], *x2 = &m->x[3 * T[2]],
                     *x3 = &m->x[3 * T[3]];
        double Dm[9];
        edge_matrix(x0, x1, x2, x3, Dm);
        double h = tet_h(fabs(m3_det(Dm)) / 6.0, x0, x1, x2, x3);
        if (!(h > 0))
            return NAN;
        dt = fmin(dt, scale * h / c_d);
    }
    return dt;
}

/* SplitMix64's finaliser (Steele, Lea, Flood 2014): a well-mixed 64-bit
 * hash of z. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* A standard normal at lattice point (i, j, k) for `seed` (Box-Muller from
 * two hashed uniforms in (0, 1)): a function of nothing but the seed and
 * the point. */
static double lattice_normal(int seed, int64_t i, int64_t j, int64_t k)
{
    uint64_t z = mix64((uint64_t)(uint32_t)seed * 0x9e3779b97f4a7c15ull + (uint64_t)i);
    z = mix64(z + (uint64_t)j * 0xc2b2ae3d27d4eb4full);
    z = mix64(z + (uint64_t)k * 0x165667b19e3779f9ull);
    double u1 = ((double)(z >> 11) + 0.5) / 9007199254740992.0;
    double u2 = ((double)(mix64(z) >> 11) + 0.5) / 9007199254740992.0;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2) /* 2 pi */;
}

/* The strength field's Weibull factor at rest point x: standard normals on
 * a cubic lattice of spacing L, blended trilinearly and rescaled to unit
 * variance (so the value is N(0, 1) everywhere and correlated over about
 * L), then mapped through the normal and Weibull distributions (a
 * translation field, Grigoriu 1995): P(w <= x) = 1 - exp(-x^m). */
static double strength_field(int seed, double L, double m, const double x[3])
{
    double q[3], sum = 0, norm = 0;
    int64_t c[3];
    for (int a = 0; a < 3; a++) {
        double y = x[a] / L, fl = floor(y);
        c[a] = (int64_t)fl, q[a] = y - fl;
    }
    for (int n = 0; n < 8; n++) {
        double w = 1;
        for (int a = 0; a < 3; a++)
            w *= (n >> a & 1) ? q[a] : 1.0 - q[a];
        sum += w * lattice_normal(seed, c[0] + (n & 1), c[1] + (n >> 1 & 1), c[2] + (n >> 2 & 1));
        norm += w * w;
    }
    double z = sum / sqrt(norm);
    /* 1 - Phi(z), without the cancellation of 1 - Phi near z = +inf */
    double survive = 0.5 * erfc(z * 0.7071067811865476) /* z / sqrt 2 */;
    return pow(-log(survive), 1.0 / m);
}

cf_status cf_solid_init_bulk_viscosity(cf_solid *s, double b1, cf_error *err)
{
    int nt = s->n_tets;
    s->bv_eta = malloc((size_t)(nt > 0 ? nt : 1) * sizeof(double));
    s->bv_rate = calloc((size_t)(nt > 0 ? nt : 1), sizeof(double));
    s->bv_work = calloc((size_t)(nt > 0 ? nt : 1), sizeof(double));
    if (!s->bv_eta || !s->bv_rate || !s->bv_work)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for the bulk viscosity of %d tets",
                            nt);
    double modulus = s->lambda + 2 * s->mu; /* rho c_d^2 */
    for (int t = 0; t < nt; t++) {
        const int *T = &s->tet0[4 * t];
        double rho = s->mat.rho * (s->mass_scale ? s->mass_scale[t] : 1.0);
        double h = tet_h(s->vol[t], &s->X[3 * T[0]], &s->X[3 * T[1]], &s->X[3 * T[2]],
                         &s->X[3 * T[3]]);
        s->bv_eta[t] = b1 * sqrt(rho * modulus) * h; /* b1 rho c_t h */
    }
    return CF_OK;
}

cf_status cf_solid_init_facets(cf_solid *s, cf_error *err)
{
    if (s->facet)
        return CF_OK;
    s->sigma = malloc((size_t)s->n_tets * 9 * sizeof(double));
    s->hot = calloc((size_t)s->n_tets, 1);
    s->qualify = calloc((size_t)s->n_tets, 1);
    s->node_mark = calloc((size_t)s->cap_nodes, 1);
    s->nodal = calloc((size_t)s->cap_nodes, sizeof(double)); /* a facet's rank may read a
                                                                 node not valued yet */
    s->nodal_stress = malloc((size_t)s->cap_nodes * 6 * sizeof(double));
    s->nodal_check = calloc((size_t)s->cap_nodes, sizeof(unsigned)); /* no check is 0 */
    s->check_stamp = 0;
    s->vert_check = calloc((size_t)(s->n_verts0 > 0 ? s->n_verts0 : 1), sizeof(unsigned));
    s->vert_node = malloc((size_t)(s->n_verts0 > 0 ? s->n_verts0 : 1) * sizeof(int));
    s->piece = malloc((size_t)s->n_tets * sizeof(int));
    s->piece_mark = calloc((size_t)s->n_tets, sizeof(unsigned));
    s->piece_stamp = 0;
    if (!s->sigma || !s->hot || !s->qualify || !s->node_mark || !s->nodal ||
        !s->nodal_stress || !s->nodal_check || !s->vert_check || !s->vert_node || !s->piece ||
        !s->piece_mark || build_facets(s))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory building facets of %d tets",
                            s->n_tets);
    const cf_material *mt = &s->mat;
    double l_ch = mt->E * mt->G_I / (mt->sigma_max * mt->sigma_max);
    s->nucleation_radius = mt->nucleation_radius > 0 ? mt->nucleation_radius : l_ch;
    cf_crack_grid_init(&s->cracks, s->nucleation_radius);
    s->strength_min = s->strength_max = 1.0;
    if (s->mat.weibull) {
        s->strength = malloc((size_t)(s->n_facets > 0 ? s->n_facets : 1) * sizeof(float));
        s->vert_wmin = malloc((size_t)(s->n_verts0 > 0 ? s->n_verts0 : 1) * sizeof(float));
        if (!s->strength || !s->vert_wmin)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for facet strengths");
        for (int o = 0; o < s->n_verts0; o++)
            s->vert_wmin[o] = INFINITY;
        /* A strength field of the material, not of the mesh (docs/physics.md
         * §5.1): the factor at the facet's rest centroid, correlated over
         * L = sqrt(A0), so two meshes of one body see the same weak regions
         * and a finer mesh offers no more weak spots per volume.  A facet
         * larger than A0 spans several independent regions and is their
         * weakest link (Zhou and Molinari 2004): scale (A0/A)^(1/m). */
        double A0 = mt->strength_area > 0 ? mt->strength_area : l_ch * l_ch, L = sqrt(A0);
        for (int f = 0; f < s->n_facets; f++) {
            const int *T = &s->tet0[4 * s->facet[4 * f]], *k = CF_TET_FACE[s->facet[4 * f + 1]];
            const double *a = &s->X[3 * T[k[0]]], *b = &s->X[3 * T[k[1]]], *c = &s->X[3 * T[k[2]]];
            double A = tri_area(a, b, c), x[3];
            for (int i = 0; i < 3; i++)
                x[i] = (a[i] + b[i] + c[i]) / 3.0;
            double size = A > A0 ? pow(A0 / A, 1.0 / mt->weibull_modulus) : 1.0;
            s->strength[f] =
                (float)(size * strength_field(mt->strength_seed, L, mt->weibull_modulus, x));
            s->strength_min = fmin(s->strength_min, s->strength[f]);
            s->strength_max = fmax(s->strength_max, s->strength[f]);
            if (s->facet[4 * f + 2] >= 0) /* a boundary face never cracks */
                for (int j = 0; j < 3; j++)
                    s->vert_wmin[T[k[j]]] = fminf(s->vert_wmin[T[k[j]]], s->strength[f]);
        }
    }
    return CF_OK;
}

double cf_front_toughness(const cf_solid *s, int t, int k, int j)
{
    const int *T = &s->tet0[4 * t], *F = CF_TET_FACE[k];
    const double *p = &s->X[3 * T[F[j]]], *a = &s->X[3 * T[F[(j + 1) % 3]]],
                 *b = &s->X[3 * T[F[(j + 2) % 3]]];
    double e[3], d[3], c[3];
    v3_sub(b, a, e), v3_sub(p, a, d), v3_cross(e, d, c);
    double r = v3_norm(c) / v3_norm(e); /* from the line through a and b */
    return s->front_K / sqrt(2 * acos(-1.0) * r);
}

/* The far stress at which a penny crack of radius a (m) is critical, Pa
 * (cf_front_penny). */
static double penny(const cf_solid *s, double a)
{
    return s->front_K * sqrt(acos(-1.0)) / (2 * sqrt(a));
}

double cf_front_penny(const cf_solid *s, int nucleus, int e0, int e1)
{
    const int *F = &s->facet[4 * nucleus], *T = &s->tet0[4 * F[0]], *K = CF_TET_FACE[F[1]];
    double d[3];
    for (int i = 0; i < 3; i++)
        d[i] = (s->X[3 * T[K[0]] + i] + s->X[3 * T[K[1]] + i] + s->X[3 * T[K[2]] + i]) / 3.0 -
               0.5 * (s->X[3 * e0 + i] + s->X[3 * e1 + i]);
    return penny(s, v3_norm(d));
}

cf_status cf_solid_init_front_toughness(cf_solid *s, int crack, cf_error *err)
{
    s->front_K = sqrt(s->mat.E * s->mat.G_I);
    float widest = INFINITY; /* with "crack", every vertex's floor */
    if (crack) {
        s->nucleus = malloc((size_t)(s->n_facets > 0 ? s->n_facets : 1) * sizeof(int));
        if (!s->nucleus)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for crack nuclei");
        for (int f = 0; f < s->n_facets; f++)
            s->nucleus[f] = f;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int o = 0; o < s->n_verts0; o++)
            for (int i = 0; i < 3; i++)
                lo[i] = fmin(lo[i], s->X[3 * o + i]), hi[i] = fmax(hi[i], s->X[3 * o + i]);
        double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        /* a penny crack as wide as the body: no front's threshold lies lower */
        widest = nextafterf((float)penny(s, v3_norm(d)), 0.0f);
    }
    s->vert_front_active = malloc((size_t)(s->n_verts0 > 0 ? s->n_verts0 : 1) * sizeof(float));
    s->vert_front_near = calloc((size_t)(s->n_verts0 > 0 ? s->n_verts0 : 1), 1);
    s->tet_floor = calloc((size_t)(s->n_tets > 0 ? s->n_tets : 1), sizeof(float));
    if (!s->vert_front_active || !s->vert_front_near || !s->tet_floor)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for front thresholds");
    for (int o = 0; o < s->n_verts0; o++)
        s->vert_front_active[o] = INFINITY;
    s->front_floor_min = INFINITY;
    for (int f = 0; f < s->n_facets; f++) {
        if (s->facet[4 * f + 2] < 0) /* a boundary face never cracks */
            continue;
        int t = s->facet[4 * f], k = s->facet[4 * f + 1];
        for (int j = 0; j < 3; j++) {
            int o = s->tet0[4 * t + CF_TET_FACE[k][j]];
            /* rounded down, so that the float never lies above a threshold */
            float th = crack ? widest : nextafterf((float)cf_front_toughness(s, t, k, j), 0.0f);
            s->vert_front_active[o] = fminf(s->vert_front_active[o], th);
            s->front_floor_min = fmin(s->front_floor_min, th);
        }
    }
    return CF_OK;
}

double cf_solid_crack_area(const cf_solid *s)
{
    double area = 0;
    for (int i = 0; i < s->n_coh; i++) {
        const cf_cohesive *c = &s->coh[i];
        if (!cf_cohesive_all_failed(c))
            continue;
        const int *tn = &s->tet[4 * c->tet[0]];
        area += tri_area(&s->X[3 * tn[c->slot[0][0]]], &s->X[3 * tn[c->slot[0][1]]],
                         &s->X[3 * tn[c->slot[0][2]]]);
    }
    return area;
}

/* Rows of 4 doubles for cap nodes, each row in one cache line (64-byte
 * aligned), holding the first n rows of old, which it frees; NULL (old
 * kept) when out of memory. */
static double *node_rows(double *old, int n, int cap)
{
    size_t bytes = ((size_t)cap * 4 * sizeof(double) + 63) & ~(size_t)63;
    double *r = aligned_alloc(64, bytes);
    if (r && old)
        memcpy(r, old, (size_t)n * 4 * sizeof(double));
    if (r)
        free(old);
    return r;
}

cf_status cf_solid_init(cf_solid *s, const cf_mesh *mesh, const cf_material *mat,
                        const int *tet_body, cf_error *err)
{
    memset(s, 0, sizeof *s);
    s->mat = *mat;
    s->lambda = mat->E * mat->nu / ((1 + mat->nu) * (1 - 2 * mat->nu));
    s->mu = mat->E / (2 * (1 + mat->nu));
    /* Drucker-Prager on Mohr-Coulomb's compression meridian, through the
     * uniaxial compressive strength (p = sigma_c / 3 there); phi = 0 is
     * von Mises at sigma_c. */
    double sphi = sin(mat->internal_friction_angle * acos(-1.0) / 180);
    s->crush_beta = 6 * sphi / (3 - sphi);
    s->crush_k = mat->compressive_strength * (1 - s->crush_beta / 3);
    int nn = mesh->n_nodes, nt = mesh->n_tets;
    s->n_nodes = s->n_verts0 = nn;
    s->cap_nodes = nn + nn / 4 + 16;
    s->n_tets = nt;
    size_t c3 = (size_t)s->cap_nodes * 3 * sizeof(double);
    s->X = malloc(c3), s->x = malloc(c3), s->v = calloc(1, c3), s->f = calloc(1, c3);
    s->p = node_rows(NULL, 0, s->cap_nodes);
    s->m = calloc((size_t)s->cap_nodes, sizeof(double));
    s->vcap = calloc((size_t)s->cap_nodes, sizeof(double));
    s->speed = calloc((size_t)s->cap_nodes, sizeof(double));
    s->origin = malloc((size_t)s->cap_nodes * sizeof(int));
    s->tet = malloc((size_t)nt * 4 * sizeof(int));
    s->tet0 = malloc((size_t)nt * 4 * sizeof(int));
    s->Dm_inv = malloc((size_t)nt * 9 * sizeof(double));
    s->vol = malloc((size_t)nt * sizeof(double));
    s->rq = malloc((size_t)nt * 4 * sizeof(double));
    s->tf = calloc((size_t)nt * 12, sizeof(double));
    s->tw = calloc((size_t)nt, sizeof(double));
    s->bc = malloc((size_t)s->cap_nodes * sizeof(int));
    s->tet_frag = malloc((size_t)nt * sizeof(int));
    if (mat->compressive_strength > 0) { /* crushing: a scene pays only for what it uses */
        s->ep = calloc((size_t)nt * 6, sizeof(double));
        s->wp = calloc((size_t)nt, sizeof(double));
        if (mat->crushing_strain > 0)
            s->crushed = calloc((size_t)nt, 1);
        if (!s->ep || !s->wp || (mat->crushing_strain > 0 && !s->crushed)) {
            cf_solid_free(s);
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for the plastic strain of %d tets",
                                nt);
        }
    }
    if (!s->X || !s->x || !s->v || !s->p || !s->f || !s->m || !s->vcap ||
        !s->speed || !s->origin || !s->tet ||
        !s->tet0 || !s->Dm_inv || !s->vol || !s->rq || !s->tf || !s->tw || !s->bc || !s->tet_frag) {
        cf_solid_free(s);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for a solid of %d tets", nt);
    }
    memcpy(s->X, mesh->x, (size_t)nn * 3 * sizeof(double));
    memcpy(s->x, mesh->x, (size_t)nn * 3 * sizeof(double));
    for (int i = 0; i < nn; i++)
        memcpy(&s->p[4 * i], &mesh->x[3 * i], 3 * sizeof(double)), s->p[4 * i + 3] = 0;
    for (int i = 0; i < nn; i++)
        s->origin[i] = i, s->bc[i] = -1;
    memcpy(s->tet, mesh->tets, (size_t)nt * 4 * sizeof(int));
    memcpy(s->tet0, mesh->tets, (size_t)nt * 4 * sizeof(int));
    memcpy(s->tet_frag, tet_body, (size_t)nt * sizeof(int));

    double c_d = wave_speed(mat);
    s->dt_cfl = INFINITY;
    for (int t = 0; t < nt; t++) {
        const int *T = &s->tet[4 * t];
        const double *x0 = &s->X[3 * T[0]], *x1 = &s->X[3 * T[1]], *x2 = &s->X[3 * T[2]],
                     *x3 = &s->X[3 * T[3]];
        double Dm[9];
        edge_matrix(x0, x1, x2, x3, Dm);
        double det = m3_inv(Dm, &s->Dm_inv[9 * t]);
        s->vol[t] = det / 6.0;
        if (!(s->vol[t] > 0)) {
            cf_solid_free(s);
            return cf_error_set(err, CF_ERR_MESH_INVERTED,
                                "tet %d has volume %.3g m^3 (inverted or degenerate): fix the mesh",
                                t, det / 6.0);
        }
        s->rq[4 * t] = 1, s->rq[4 * t + 1] = s->rq[4 * t + 2] = s->rq[4 * t + 3] = 0;
        s->dt_cfl = fmin(s->dt_cfl, tet_h(s->vol[t], x0, x1, x2, x3) / c_d);
    }
    if (build_vertex_tets(s)) {
        cf_solid_free(s);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for the node-to-tet map of %d tets",
                            nt);
    }
    for (int t = 0; t < nt; t++) /* lumped mass: rho V / 4 to each node */
        for (int j = 0; j < 4; j++)
            s->m[s->tet[4 * t + j]] += mat->rho * s->vol[t] / 4.0;
    return CF_OK;
}

cf_status cf_solid_scale_mass(cf_solid *s, double floor, cf_error *err)
{
    int nt = s->n_tets;
    if (!(floor > 0) || nt == 0)
        return CF_OK;
    double c_d = wave_speed(&s->mat), *dt = malloc((size_t)2 * nt * sizeof(double));
    s->mass_scale = malloc((size_t)nt * sizeof(double));
    if (!dt || !s->mass_scale) {
        free(dt);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory scaling the mass of %d tets", nt);
    }
    double *sorted = dt + nt; /* rest stable steps h / c_d (§3), then sorted */
    for (int t = 0; t < nt; t++) {
        const int *T = &s->tet0[4 * t];
        dt[t] = sorted[t] = tet_h(s->vol[t], &s->X[3 * T[0]], &s->X[3 * T[1]], &s->X[3 * T[2]],
                                  &s->X[3 * T[3]]) / c_d;
    }
    cf_doubles_sort(sorted, nt);
    double least = floor * sorted[nt / 2];
    s->dt_cfl = INFINITY;
    for (int t = 0; t < nt; t++) {
        /* The wave speed falls as 1/sqrt(density), so the step grows as its
         * square root. */
        double scale = dt[t] < least ? (least / dt[t]) * (least / dt[t]) : 1.0;
        double mass = s->mat.rho * s->vol[t], added = (scale - 1.0) * mass;
        s->mass_scale[t] = scale;
        s->dt_cfl = fmin(s->dt_cfl, fmax(dt[t], least));
        s->mass_total += mass + added;
        if (scale == 1.0)
            continue;
        for (int j = 0; j < 4; j++)
            s->m[s->tet[4 * t + j]] += added / 4.0;
        s->mass_added += added;
        s->mass_scale_max = fmax(s->mass_scale_max, scale);
        s->n_mass_scaled++;
    }
    free(dt);
    return CF_OK;
}

void cf_solid_free(cf_solid *s)
{
    void *ptrs[] = {s->X, s->x, s->v, s->p, s->f, s->m, s->vcap, s->speed, s->mass_scale,
                    s->origin, s->tet, s->tet0,
                    s->Dm_inv, s->vol, s->rq, s->sigma, s->hot, s->qualify, s->node_mark,
                    s->nodal, s->nodal_stress, s->nodal_check, s->vert_check, s->vert_node, s->piece, s->piece_mark, s->tf, s->tw, s->ep, s->wp, s->crushed, s->bc, s->tet_frag, s->facet, s->tet_facet,
                    s->cracked, s->tet_open, s->edge_cracks, s->crack_time, s->candidate, s->strength, s->vert_wmin, s->vert_front_active, s->nucleus, s->vert_front_near, s->tet_floor, s->vt_start, s->vt_slot, s->coh, s->coh_fric,
                    s->vert_cracks, s->contact_key, s->contact_kind, s->contact_until,
                    s->bv_eta, s->bv_rate, s->bv_work};
    for (size_t i = 0; i < sizeof ptrs / sizeof ptrs[0]; i++)
        free(ptrs[i]);
    cf_crack_grid_free(&s->cracks);
    memset(s, 0, sizeof *s);
}

static int grow(void **p, size_t elem, int newcap)
{
    void *q = realloc(*p, elem * (size_t)newcap);
    if (!q)
        return -1;
    *p = q;
    return 0;
}

int cf_solid_copy_node(cf_solid *s, int n)
{
    if (s->n_nodes == s->cap_nodes) {
        int cap = s->cap_nodes * 3 / 2 + 16;
        size_t v3 = 3 * sizeof(double);
        double *p = node_rows(s->p, s->n_nodes, cap);
        if (!p)
            return -1;
        s->p = p;
        if (grow((void **)&s->X, v3, cap) || grow((void **)&s->x, v3, cap) ||
            grow((void **)&s->v, v3, cap) ||
            grow((void **)&s->f, v3, cap) || grow((void **)&s->m, sizeof(double), cap) ||
            grow((void **)&s->vcap, sizeof(double), cap) ||
            grow((void **)&s->speed, sizeof(double), cap) ||
            grow((void **)&s->origin, sizeof(int), cap) || grow((void **)&s->bc, sizeof(int), cap))
            return -1;
        if (s->node_mark && (grow((void **)&s->node_mark, 1, cap) ||
                             grow((void **)&s->nodal, sizeof(double), cap) ||
                             grow((void **)&s->nodal_stress, 6 * sizeof(double), cap) ||
                             grow((void **)&s->nodal_check, sizeof(unsigned), cap)))
            return -1;
        if (s->node_mark) {
            memset(s->node_mark + s->cap_nodes, 0, (size_t)(cap - s->cap_nodes));
            memset(s->nodal + s->cap_nodes, 0, (size_t)(cap - s->cap_nodes) * sizeof(double));
            memset(s->nodal_check + s->cap_nodes, 0,
                   (size_t)(cap - s->cap_nodes) * sizeof(unsigned));
        }
        s->cap_nodes = cap;
    }
    int k = s->n_nodes++;
    memcpy(&s->X[3 * k], &s->X[3 * n], 3 * sizeof(double));
    memcpy(&s->x[3 * k], &s->x[3 * n], 3 * sizeof(double));
    memcpy(&s->v[3 * k], &s->v[3 * n], 3 * sizeof(double));
    memcpy(&s->p[4 * k], &s->p[4 * n], 4 * sizeof(double));
    s->f[3 * k] = s->f[3 * k + 1] = s->f[3 * k + 2] = 0;
    s->m[k] = 0;
    s->origin[k] = s->origin[n];
    s->bc[k] = s->bc[n];
    return k;
}

int cf_solid_star_gradient(const cf_solid *s, int o, double F[9])
{
    int lo = s->vt_start[o], hi = s->vt_start[o + 1], n = s->tet[s->vt_slot[lo]];
    double vsum = 0;
    memset(F, 0, 9 * sizeof(double));
    for (int i = lo; i < hi; i++) {
        int t = s->vt_slot[i] / 4;
        const int *C = &s->tet[4 * t];
        if (C[s->vt_slot[i] % 4] != n) /* a crack parts the star */
            return 0;
        double Ds[9], Ft[9];
        edge_matrix(&s->x[3 * C[0]], &s->x[3 * C[1]], &s->x[3 * C[2]], &s->x[3 * C[3]], Ds);
        m3_mul(Ds, &s->Dm_inv[9 * t], Ft);
        for (int k = 0; k < 9; k++)
            F[k] += s->vol[t] * Ft[k];
        vsum += s->vol[t];
    }
    for (int k = 0; k < 9; k++)
        F[k] /= vsum;
    return 1;
}

int cf_solid_move_vertex(cf_solid *s, int o, const double to[3], const double F[9],
                         double least_h)
{
    enum { MOST = 128 };
    int lo = s->vt_start[o], ns = s->vt_start[o + 1] - lo, n = s->tet[s->vt_slot[lo]];
    if (ns > MOST)
        return 0;
    double Dinv[MOST][9], vol[MOST], hmin = s->dt_cfl * wave_speed(&s->mat);
    for (int i = 0; i < ns; i++) {
        int t = s->vt_slot[lo + i] / 4;
        const int *T = &s->tet0[4 * t];
        for (int k = 0; s->ep && k < 6; k++) /* a plastic strain holds the old shape */
            if (s->ep[6 * t + k] != 0)
                return 0;
        const double *p[4], *q[4];
        for (int j = 0; j < 4; j++)
            p[j] = T[j] == o ? to : &s->X[3 * T[j]], q[j] = &s->X[3 * T[j]];
        double Dm[9];
        edge_matrix(p[0], p[1], p[2], p[3], Dm);
        vol[i] = m3_inv(Dm, Dinv[i]) / 6.0;
        if (!(vol[i] > 0) || tet_h(vol[i], p[0], p[1], p[2], p[3]) <
                                 fmax(hmin, least_h * tet_h(s->vol[t], q[0], q[1], q[2], q[3])))
            return 0;
    }
    double d[3], dx[3];
    v3_sub(to, &s->X[3 * o], d);
    m3_mulv(F, d, dx);
    for (int k = 0; k < 3; k++) {
        s->x[3 * n + k] += dx[k], s->p[4 * n + k] = s->x[3 * n + k];
        s->X[3 * n + k] = s->X[3 * o + k] = to[k];
    }
    /* re-lumped masses (rho V / 4 of each tet), each node keeping its momentum */
    for (int i = 0; i < ns; i++) {
        int t = s->vt_slot[lo + i] / 4;
        double dm = cf_tet_mass(s, t) * (vol[i] / s->vol[t] - 1) / 4;
        for (int j = 0; j < 4; j++) {
            int a = s->tet[4 * t + j];
            double m0 = s->m[a];
            s->m[a] += dm;
            for (int k = 0; k < 3; k++)
                s->v[3 * a + k] *= m0 / s->m[a];
        }
        memcpy(&s->Dm_inv[9 * t], Dinv[i], sizeof Dinv[i]);
        s->vol[t] = vol[i];
    }
    return 1;
}
