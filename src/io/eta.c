/* The run's remaining wall time: see eta.h. */
#include "eta.h"

#include <math.h>
#include <string.h>

#define CF_ETA_SPACING 0.25 /* s of wall between samples at first */
#define CF_ETA_LONG 4       /* a spell of more quiet times than this is long */
#define CF_ETA_RECENT 0.2   /* of the wall so far: the window of the cost per tet-step */
#define CF_ETA_RECENT_MIN 2 /* s of wall, the window's least */
#define CF_ETA_REST_MIN 50  /* quiet times outside long spells that give their rate */

void cf_eta_init(cf_eta *e, const cf_eta_rule *rule)
{
    memset(e, 0, sizeof *e);
    e->rule = *rule;
    e->spacing = CF_ETA_SPACING;
}

/* The wall between two samples goes to the rest of the run unless a long
 * spell took it.  A spell's wall is held back (pending) until it ends,
 * with the interval it ends in (its pieces' hand-offs): a short spell (a
 * piece that lands again) is part of the rest, at the rate such landings
 * came; the impact that breaks the body is not. */
static void account(cf_eta *e, const cf_eta_sample *a, const cf_eta_sample *b)
{
    double wall = b->wall - a->wall, dt = b->t - a->t;
    if (a->spell > 0 || b->spell > 0)
        e->pending_wall += wall, e->pending_t += dt;
    else
        e->rest_wall += wall, e->rest_t += dt;
    if (a->spell > 0 && b->spell < a->spell + dt - 1e-15) { /* it ended (another may run) */
        if (a->spell <= CF_ETA_LONG * e->rule.quiet_time)
            e->rest_wall += e->pending_wall, e->rest_t += e->pending_t;
        e->pending_wall = e->pending_t = 0;
    }
}

void cf_eta_add(cf_eta *e, const cf_eta_sample *s)
{
    if (e->n > 0)
        account(e, &e->s[e->n - 1], s); /* the newest sample is always the last one kept */
    if (e->n > 1 && s->wall - e->s[e->n - 2].wall < e->spacing) {
        e->s[e->n - 1] = *s; /* too close to the one before: the newest replaces it */
        return;
    }
    if (e->n == CF_ETA_KEEP) { /* full: keep every other one, twice as far apart */
        for (int i = 0; i < CF_ETA_KEEP / 2; i++)
            e->s[i] = e->s[2 * i];
        e->n = CF_ETA_KEEP / 2;
        e->spacing *= 2;
    }
    e->s[e->n++] = *s;
}

/* The cracks at simulated time t, linear between samples.  Returns 0 where
 * the history does not reach back that far. */
static int cracks_at(const cf_eta *e, double t, double *out)
{
    if (e->n == 0 || t < e->s[0].t)
        return 0;
    for (int i = e->n - 1; i > 0; i--) {
        const cf_eta_sample *a = &e->s[i - 1], *b = &e->s[i];
        if (t >= a->t) {
            double u = b->t > a->t ? (t - a->t) / (b->t - a->t) : 1;
            *out = a->cracks + fmin(u, 1.0) * (b->cracks - a->cracks);
            return 1;
        }
    }
    *out = e->s[0].cracks;
    return 1;
}

/* Simulated time, s, since the cracks last grew by what the quiet rule
 * takes for some (`some` cohesive elements). */
static double quiet_for(const cf_eta *e, double some)
{
    const cf_eta_sample *now = &e->s[e->n - 1];
    for (int i = e->n - 2; i >= 0; i--)
        if (e->s[i].cracks < now->cracks - some)
            return now->t - e->s[i].t;
    return now->t - e->s[0].t;
}

/* Cracks grow fast in an impact and then fewer at a time, about
 * exponentially (the 202,231-tet plaster drop inserted 38,777, 20,676,
 * 6,878 and 3,633 cohesive elements in the half milliseconds from 0.5 to
 * 2.5 ms); the quiet rule ends the spell once they grow by less than
 * quiet_growth of the cracks in a quiet time.  Over two quarters of the
 * spell the mean rates r0, r1 give the decay time tau = d / ln(r0/r1), the
 * rate now, r1 u / (e^u - 1) with u = d / tau, and the cracks at the end,
 * now + rate tau: exact for an exponential, and taken up to as much
 * again as the spell has run (a decay barely begun, r0 near r1, gives
 * tau without bound).  That is the earliest end: each fragment goes quiet
 * by its own count, and a landing not yet over holds it (the 202,231-tet
 * drop's break ran 0.5 ms past the end its cracks as a whole gave, the
 * 15,040-tet drop's 0.3 ms); as much again as the spell has run is the
 * latest one looked for.  The spell is given their geometric mean.
 * Where the cracks no longer grow, a landing or a crushing holds the spell
 * (each crushed tet restarts the quiet count, §9): what the landings under
 * way still hold it, where known, or as long again as they have been
 * quiet. */
double cf_eta_spell_left(const cf_eta *e, double held, int *by_landing)
{
    *by_landing = isfinite(held);
    if (e->n == 0 || e->s[e->n - 1].spell <= 0) /* none, or begun since the last sample */
        return isfinite(held) ? fmin(fmax(0.0, held), e->rule.max_spell) : 0;
    const cf_eta_sample *now = &e->s[e->n - 1];
    double s = now->spell, q = e->rule.quiet_time, d = s / 4, c0, c1;
    double left = fmax(s, held); /* no measure of the end: as much again */
    *by_landing = held > s;
    if (s > 2 * q && cracks_at(e, now->t - 2 * d, &c0) && cracks_at(e, now->t - d, &c1)) {
        double r0 = (c1 - c0) / d, r1 = (now->cracks - c1) / d; /* per s simulated */
        double some = fmax(e->rule.quiet_growth * now->cracks, 1.0), none = some / q;
        *by_landing = r1 <= none && isfinite(held);
        if (r1 <= none) /* quiet: the rule ends it within a quiet time, or a landing or a
                           crushing holds it, for about as long again as it has held it */
            left = fmax(q, isfinite(held) ? held : fmin(s, quiet_for(e, some)));
        else if (r1 < r0) {
            double u = log(r0 / r1), tau = d / u, rate = r1 * u / (r0 / r1 - 1);
            none = fmax(e->rule.quiet_growth * (now->cracks + rate * tau), 1.0) / q;
            double decay = fmin(s, (rate > none ? tau * log(rate / none) : 0) + q);
            left = sqrt(decay * s);
            *by_landing = held > left; /* the landings under way hold it at least that long */
            left = fmax(left, held);
        }
    }
    return fmax(0.0, fmin(left, e->rule.max_spell - s));
}

/* A landing's spell lasts about its landing time, the quiet count running
 * while the floor holds the piece: the 73 spells of the 202,231-tet drop's
 * pieces after its break, of 10 to 31,602 tets, ran 0.25-1.5 times theirs
 * (0.95 weighted by their tets; the 31,602-tet piece 1.70 ms against
 * 1.73 ms). */
double cf_eta_landing_spell(const cf_eta *e, const cf_eta_landing *l, double t_left)
{
    double q = e->rule.quiet_time, spell = fmax(l->hold, q);
    if (spell <= CF_ETA_LONG * q || l->under_way || l->t >= t_left)
        return 0;
    return fmin(spell, t_left - l->t);
}

double cf_eta_left(const cf_eta *e, double t_left, double tets, const cf_eta_landing *landing,
                   int n_landing, double frame_cost)
{
    if (e->n == 0)
        return frame_cost;
    const cf_eta_sample *now = &e->s[e->n - 1];
    /* The cost per tet-step over the recent wall: it grows as the cracks
     * multiply (the 202,231-tet drop's 0.9-1.0 ms cost twice its first
     * millisecond's average). */
    double window = fmax(CF_ETA_RECENT_MIN, CF_ETA_RECENT * now->wall);
    const cf_eta_sample *old = &e->s[0];
    for (int i = e->n - 1; i >= 0; i--)
        if (e->s[i].wall <= now->wall - window) {
            old = &e->s[i];
            break;
        }
    double per_tet_step = 0, run_per_tet_step = 0;
    if (now->tet_steps > 0)
        run_per_tet_step = now->fracture_wall / now->tet_steps;
    if (now->tet_steps > old->tet_steps)
        per_tet_step = (now->fracture_wall - old->fracture_wall) / (now->tet_steps - old->tet_steps);
    else
        per_tet_step = run_per_tet_step;
    /* The landings under way hold the spell up to their landing times:
       the crack growth of a landing that breaks nothing says nothing of
       it (the 202,231-tet drop's 31,602-tet piece, 1.7 ms of fracture
       mode and 66 s of wall, read 13 s, then as long again as it had
       run).  Not before a quiet time of steps has run: until then the
       cost per tet-step holds the run's first hand-off. */
    double held = -INFINITY;
    int measured = e->rule.dt > 0 && now->tet_steps >= tets * e->rule.quiet_time / e->rule.dt;
    for (int i = 0; i < n_landing && measured; i++)
        if (landing[i].under_way)
            held = fmax(held, landing[i].hold + landing[i].t);
    /* A landing's spell, under way or to come, at the run's cost per
       tet-step: a large piece costs what the break's many tets cost each,
       where the recent wall holds the small pieces' short spells, whose
       fixed cost per step over a few tets reads as several times as much
       on the 15,040-tet drop. */
    int by_landing;
    double spell = fmin(cf_eta_spell_left(e, held, &by_landing), t_left);
    double cost = by_landing ? run_per_tet_step : per_tet_step;
    double spell_rate = e->rule.dt > 0 ? cost * tets / e->rule.dt : 0; /* s per s */
    double landings = 0; /* tet-seconds simulated */
    for (int i = 0; i < n_landing; i++)
        landings += landing[i].tets * cf_eta_landing_spell(e, &landing[i], t_left);
    if (e->rule.dt > 0)
        landings *= run_per_tet_step / e->rule.dt;
    /* Outside long spells: measured there once it has run a while (the
     * start of a run that begins with an impact holds the body's hand-off
     * and decomposition: 0.3 s over 0.1 ms), or the recent rigid steps
     * alone (their pieces multiply during the impact). */
    double rest_rate = 0;
    if (e->rest_t >= CF_ETA_REST_MIN * e->rule.quiet_time)
        rest_rate = e->rest_wall / e->rest_t;
    else if (now->t > old->t)
        rest_rate = (now->wall - now->fracture_wall - old->wall + old->fracture_wall) /
                    (now->t - old->t);
    return spell * spell_rate + landings + (t_left - spell) * rest_rate + frame_cost;
}
