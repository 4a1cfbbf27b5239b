/* The settings schema (cohfrac/settings.h): its table, the defaults it
 * gives, and the rules between settings. */
#include "cohfrac/settings.h"

#include <string.h>

/* Enum spellings, by the enums' values (cohfrac/types.h). */
static const char *const cf_names_strength[] = {"uniform", "weibull", NULL};
static const char *const cf_names_mode[] = {"hybrid", "fracture", NULL};
static const char *const cf_names_backend[] = {"bullet", "pbd", NULL};
static const char *const cf_names_elasticity[] = {"corotational", "linear", NULL};
static const char *const cf_names_criterion[] = {"traction", "source", "none", NULL};
static const char *const cf_names_growth[] = {"fronts", "all", NULL};
static const char *const cf_names_front[] = {"any", "stress", NULL};
static const char *const cf_names_front_threshold[] = {"strength", "toughness", "crack", NULL};
static const char *const cf_names_front_split[] = {"none", "plane", NULL};
static const char *const cf_names_front_snap[] = {"none", "stress", NULL};
static const char *const cf_names_time_continuity[] = {"tangential", "both", NULL};
static const char *const cf_names_obstacle_contact[] = {"kinematic", "penalty", NULL};
static const char *const cf_names_constraints[] = {"pbd", "xpbd", "none", NULL};
_Static_assert(CF_RUN_HYBRID == 0 && CF_RUN_FRACTURE == 1, "cf_names_mode follows cf_run_mode");
_Static_assert(CF_RIGID_BULLET == 0 && CF_RIGID_PBD == 1, "cf_names_backend");
_Static_assert(CF_ELASTICITY_COROTATIONAL == 0 && CF_ELASTICITY_LINEAR == 1,
               "cf_names_elasticity");
_Static_assert(CF_CRITERION_TRACTION == 0 && CF_CRITERION_SOURCE == 1 && CF_CRITERION_NONE == 2,
               "cf_names_criterion");
_Static_assert(CF_GROWTH_FRONTS == 0 && CF_GROWTH_ALL == 1, "cf_names_growth");
_Static_assert(CF_FRONT_ANY == 0 && CF_FRONT_STRESS == 1, "cf_names_front");
_Static_assert(CF_FRONT_STRENGTH == 0 && CF_FRONT_TOUGHNESS == 1 && CF_FRONT_CRACK == 2,
                "cf_names_front_threshold");
_Static_assert(CF_FRONT_SPLIT_NONE == 0 && CF_FRONT_SPLIT_PLANE == 1, "cf_names_front_split");
_Static_assert(CF_FRONT_SNAP_NONE == 0 && CF_FRONT_SNAP_STRESS == 1, "cf_names_front_snap");
_Static_assert(CF_CONTINUITY_TANGENTIAL == 0 && CF_CONTINUITY_BOTH == 1,
               "cf_names_time_continuity");
_Static_assert(CF_OBSTACLE_CONTACT_KINEMATIC == 0 && CF_OBSTACLE_CONTACT_PENALTY == 1,
               "cf_names_obstacle_contact");
_Static_assert(CF_CONSTRAINTS_PBD == 0 && CF_CONSTRAINTS_XPBD == 1 && CF_CONSTRAINTS_NONE == 2,
               "cf_names_constraints");

const cf_setting *cf_settings(int *n)
{
#define CF_SETTING_(table, key, kind, field, def, from, names, range, unit, doc)                \
    {table, key, CF_SET_##kind, offsetof(cf_world_def, field), def, from, names, range, unit,  \
     doc},
    static const cf_setting schema[] = {CF_SETTINGS(CF_SETTING_)};
#undef CF_SETTING_
    *n = (int)(sizeof schema / sizeof schema[0]);
    return schema;
}

const cf_setting *cf_setting_find(const char *table, const char *key)
{
    int n;
    const cf_setting *e = cf_settings(&n);
    for (int i = 0; i < n; i++)
        if (!strcmp(e[i].table, table) && !strcmp(e[i].key, key))
            return &e[i];
    return NULL;
}

double cf_setting_get(const cf_setting *e, const cf_world_def *d)
{
    const char *p = (const char *)d + e->offset;
    if (e->kind == CF_SET_NUM)
        return *(const double *)p;
    int v;
    memcpy(&v, p, sizeof v);
    return v;
}

void cf_setting_set(const cf_setting *e, cf_world_def *d, double v)
{
    char *p = (char *)d + e->offset;
    if (e->kind == CF_SET_NUM) {
        *(double *)p = v;
    } else if (e->kind != CF_SET_TABLE && e->kind != CF_SET_CUSTOM) {
        int i = (int)v;
        memcpy(p, &i, sizeof i);
    }
}

cf_status cf_solver_check_rules(const cf_solver_settings *s, cf_error *err)
{
    /* Bullet compares both speeds: a 0 in one would keep every body awake. */
    if ((s->sleep_linear > 0.0) != (s->sleep_angular > 0.0))
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.sleeping' needs linear and angular both > 0 (or both 0: no "
                            "sleeping), got linear = %g m/s, angular = %g rad/s",
                            s->sleep_linear, s->sleep_angular);
    if (s->dt_fracture > s->dt_rigid)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_fracture' must not exceed solver.dt_rigid (%g), got %g",
                            s->dt_rigid, s->dt_fracture);
    if (s->dt_rigid / s->dt_fracture > CF_MAX_SUBSTEPS)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_rigid' / 'solver.dt_fracture' = %.3g fracture steps in one "
                            "rigid step, above the limit %d: lower solver.dt_rigid or raise "
                            "solver.dt_fracture",
                            s->dt_rigid / s->dt_fracture, CF_MAX_SUBSTEPS);
    return CF_OK;
}
