/* Position based dynamics (docs/physics.md §7, source §6.2; Müller et al. 2007) and
 * the obstacles of the collision constraints. */
#ifndef COHFRAC_PBD_H
#define COHFRAC_PBD_H

#include "cohfrac/types.h"
#include "solid.h"

#include <stdint.h>

/* One bar per unique edge of the current tets, rest length from s->X.
 * XPBD compliance of a bar: L^2 / (E V_trib) (m/N), V_trib the sum of a
 * sixth of the volume of every tet that has the edge, so that a bar is a rod
 * of section V_trib / L of the bulk material. */
#define CF_BARS_COLORS 128        /* colours; bars beyond them go to one serial group */
#define CF_BARS_PARALLEL_MIN 4096 /* fewer bars: the sweep runs on one thread */

typedef struct cf_bars {
    int n, cap;         /* bars, and room for them */
    int n_colors;       /* colour groups used */
    int *color_start;   /* [CF_BARS_COLORS + 2]: bars of colour c are color_start[c] ..
                           color_start[c+1] - 1; the serial group from
                           color_start[CF_BARS_COLORS] to n - 1; NULL where the
                           fragment keeps no bars, as no step reads them
                           (cf_world_reads_bars): patched and split as none */
    int *ends;          /* [n][2] node indices, ascending pairs, grouped by colour */
    double *rest;       /* [n] m */
    double *compliance; /* [n] m/N */
    double *lambda;     /* [n] XPBD Lagrange multipliers of this step, N s^2 */
} cf_bars;

/* (Re)build the bars of `tets`: node by node through the solid's
 * vertex-to-tet map (no global sort; parallel over nodes), then coloured
 * greedily so that no two bars of a colour share a node.  Returns 0, or -1
 * when out of memory. */
int cf_bars_build(cf_bars *b, const cf_solid *s, const int *tets, int nt);
void cf_bars_free(cf_bars *b);

/* Scratch of cf_bars_patch, kept between calls so that an inserting step
 * does not allocate (grown when the solid's nodes or the new bars need it). */
typedef struct cf_bars_scratch {
    int node_cap, bar_cap;
    unsigned char *flag;      /* [node_cap] 0 between calls */
    uint64_t (*mask)[2];      /* [node_cap] colours used at a node */
    int *list;                /* [node_cap] the nodes flagged */
    int *ends;                /* [bar_cap][2] the new bars */
    double *rest, *compliance;
    unsigned char *colour;
} cf_bars_scratch;
void cf_bars_scratch_free(cf_bars_scratch *w);

/* The bars after node duplication, patched where the mesh changed instead
 * of rebuilt: the bars at the `touched` nodes (the nodes whose star of tets
 * changed: each split node and its new copies; repeats allowed) are dropped
 * and made anew from their stars; every other bar keeps its rest length,
 * compliance and colour, and the new ones take the lowest colour free at
 * both ends (in ascending node order).  The bar set equals
 * cf_bars_build's; the colouring is a valid one, not the same.  Returns 0,
 * or -1 when out of memory. */
int cf_bars_patch(cf_bars *b, const cf_solid *s, const int *touched, int n_touched,
                  cf_bars_scratch *w);

/* Split the bars of a fragment among the k pieces it fell into (no bar
 * joins two pieces): bar i goes to dst[piece_of_node[its first end]], in
 * order and with its colour.  Returns 0, or -1 when out of memory. */
int cf_bars_split(const cf_bars *src, const int *piece_of_node, int k, cf_bars *const *dst);

/* One Gauss-Seidel sweep over the bars on the predictions s->p, colour
 * after colour (in parallel within a colour; the same bits for any thread
 * count), with the inverse masses w = 1/m from slot 3 of s->p's rows (set
 * by the caller for the bars' nodes):
 * C = |p1 - p2| - d, dp1 = -w1/(w1+w2) C n, dp2 = +w2/(w1+w2) C n, scaled by k.
 * With speed and cap (else NULL) the same pass also does
 * cf_bars_neighbour_speed's update at each bar: one pass over the bars
 * instead of two, and the same caps (a maximum in any order is exact). */
void cf_bars_project(const cf_bars *b, cf_solid *s, double k, const double *speed, double *cap);

/* cap[a] = max(cap[a], speed[c]) for every bar (a, c), both ways (m/s):
 * the fastest neighbour of each node.  Colour by colour, like the sweep. */
void cf_bars_neighbour_speed(const cf_bars *b, const double *speed, double *cap);

/* The stiffness used per iteration: k, or with `iteration_independent`
 * k' = 1 - (1 - k)^(1/iterations) (Müller et al. 2007, §3.3), so that the
 * stiffness after all iterations does not depend on their number. */
double cf_pbd_effective_stiffness(double k, int iterations, int iteration_independent);

/* One XPBD sweep (Macklin, Müller, Chentanez 2016, eq. 18; w as for cf_bars_project): with
 * alpha~ = scale compliance / dt^2, dlambda = (-C - alpha~ lambda)/(w1 + w2 +
 * alpha~), p1 += w1 dlambda n, p2 -= w2 dlambda n.  Reset lambda with
 * cf_bars_reset_lambda at the start of every step. */
void cf_bars_project_xpbd(cf_bars *b, cf_solid *s, double dt, double scale);
void cf_bars_reset_lambda(cf_bars *b);

#endif
