// cohfrac — Bullet rigid-body world behind the C header cf_bullet.h.
// Built with BT_USE_DOUBLE_PRECISION and -fno-exceptions: nothing here throws,
// and no C++ type leaves this file.
#include "cf_bullet.h"

#include <btBulletDynamicsCommon.h>
#include <LinearMath/btConvexHullComputer.h>

#include <LinearMath/btAlignedAllocator.h>
#include <malloc.h>

#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <new>
#include <vector>

namespace {

// Per thread, so OpenMP callers do not overwrite each other's message.
thread_local char g_error[256] = "";

void set_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(g_error, sizeof g_error, fmt, ap);
    va_end(ap);
}

bool finite3(const double *v)
{
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

bool nonzero3(const double *v) { return v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0; }

enum BodyKind { BODY_DYNAMIC, BODY_STATIC, BODY_KINEMATIC };

struct Body {
    btRigidBody *rb;
    btCollisionShape *shape;
    btDefaultMotionState *motion;
    BodyKind kind;
    btVector3 kin_v, kin_w;  // prescribed velocity of a kinematic obstacle
    double impulse;          // normal contact impulse during the last cfb_step
    double impulse_static;   // the part of it from static bodies
    std::vector<int> ignored;
    // The quaternion last given by the caller and the basis it produced:
    // while the basis is untouched, get_state returns that exact quaternion
    // (matrix -> quaternion conversion would differ by round-off or sign).
    bool has_quat;
    double quat[4];
    btMatrix3x3 quat_basis;
    // Owned by the body besides `shape`: the children of a compound shape,
    // and the arrays of a triangle mesh (Bullet keeps pointers into them).
    std::vector<btCollisionShape *> children;
    btTriangleIndexVertexArray *mesh;
    std::vector<btScalar> mesh_verts;
    std::vector<int> mesh_tris;
};

// Exposes the fixed-step accumulator so each cfb_step runs a whole number of
// sub-steps with nothing carried over between calls.
class StepWorld : public btDiscreteDynamicsWorld {
public:
    StepWorld(btDispatcher *d, btBroadphaseInterface *b, btConstraintSolver *s,
              btCollisionConfiguration *c)
        : btDiscreteDynamicsWorld(d, b, s, c)
    {
    }
    void reset_local_time() { m_localTime = 0; }
};

// Bodies of one collision family (user index 2, -1 = none) never collide
// with each other.
bool same_family(const btCollisionObject *a, const btCollisionObject *b)
{
    const int fa = a->getUserIndex2();
    return fa >= 0 && fa == b->getUserIndex2();
}

// Checked by the CCD sweep (Bullet 3.24's btClosestNotMeConvexResultCallback
// asks the dispatcher's needsCollision), so CCD does not stop a body at a
// member of its family or an ignored partner either.
class FamilyDispatcher : public btCollisionDispatcher {
public:
    explicit FamilyDispatcher(btCollisionConfiguration *c) : btCollisionDispatcher(c) {}
    bool needsCollision(const btCollisionObject *a, const btCollisionObject *b) override
    {
        if (same_family(a, b)) return false;
        return btCollisionDispatcher::needsCollision(a, b);
    }
};

// And kept out of the broadphase's pair cache: a shattered body's pieces
// lie in one heap, and the pairs among them, rejected again at every step
// by the dispatcher, still went through the island unions and the near
// callback (most of the rigid step after the 203k-tet plaster drop's
// break, its 2,700 debris pieces on the floor).
class FamilyFilter : public btOverlapFilterCallback {
public:
    bool needBroadphaseCollision(btBroadphaseProxy *p0, btBroadphaseProxy *p1) const override
    {
        if (!(p0->m_collisionFilterGroup & p1->m_collisionFilterMask) ||
            !(p1->m_collisionFilterGroup & p0->m_collisionFilterMask))
            return false;  // Bullet's default test
        return !same_family(static_cast<const btCollisionObject *>(p0->m_clientObject),
                            static_cast<const btCollisionObject *>(p1->m_clientObject));
    }
};

}  // namespace

struct cfb_world {
    btDefaultCollisionConfiguration *config;
    FamilyDispatcher *dispatcher;
    FamilyFilter *filter;
    btDbvtBroadphase *broadphase;
    btSequentialImpulseConstraintSolver *solver;
    StepWorld *dyn;
    std::vector<Body *> bodies;  // index = id; removed slots are NULL
    std::vector<Body *> kinematic;
    int n_dynamic;
    int ticks;  // sub-steps run by the current cfb_step
    // Sleeping thresholds (m/s, rad/s) for dynamic bodies; 0, 0 = never.
    double sleep_linear, sleep_angular;
    // Bullet ran out of memory in a call that cannot return an error (a
    // void one): the next cfb_step fails with it.
    bool out_of_memory;
};

namespace {

Body *lookup(const cfb_world *w, int id)
{
    if (!w) {
        set_error("world is NULL");
        return NULL;
    }
    if (id < 0 || static_cast<size_t>(id) >= w->bodies.size() || !w->bodies[id]) {
        set_error("invalid body id %d", id);
        return NULL;
    }
    return w->bodies[id];
}

bool state_valid(const cfb_state *s)
{
    if (!s) {
        set_error("state is NULL");
        return false;
    }
    const double q2 = s->quat[0] * s->quat[0] + s->quat[1] * s->quat[1] +
                      s->quat[2] * s->quat[2] + s->quat[3] * s->quat[3];
    if (!finite3(s->pos) || !finite3(s->v) || !finite3(s->w) || !std::isfinite(q2)) {
        set_error("state has a non-finite value");
        return false;
    }
    if (!(q2 > 1e-30)) {
        set_error("state quaternion is zero");
        return false;
    }
    return true;
}

// Caller's quaternion, normalised only when it is not already unit to
// round-off (so a unit input is kept bit for bit).
void unit_quat(const double in[4], double out[4])
{
    const double q2 = in[0] * in[0] + in[1] * in[1] + in[2] * in[2] + in[3] * in[3];
    const double f = std::fabs(q2 - 1.0) > 1e-14 ? 1.0 / std::sqrt(q2) : 1.0;
    for (int i = 0; i < 4; ++i) out[i] = in[i] * f;
}

btTransform state_transform(const double q[4], const double p[3])
{
    // cfb order is (w,x,y,z); btQuaternion takes (x,y,z,w).
    return btTransform(btQuaternion(q[1], q[2], q[3], q[0]), btVector3(p[0], p[1], p[2]));
}

void remember_quat(Body *b, const double q[4])
{
    b->has_quat = true;
    for (int i = 0; i < 4; ++i) b->quat[i] = q[i];
    b->quat_basis = b->rb->getCenterOfMassTransform().getBasis();
}

bool friction_valid(double friction, double restitution)
{
    if (!std::isfinite(friction) || friction < 0.0 || !std::isfinite(restitution) ||
        restitution < 0.0) {
        set_error("friction and restitution must be finite and >= 0");
        return false;
    }
    return true;
}

// Sleeping is off by default so that runs are reproducible and contact
// impulses are reported every step (DISABLE_DEACTIVATION).  With thresholds
// set (cfb_set_sleeping) dynamic bodies go to ACTIVE_TAG and Bullet puts an
// island to sleep once all its bodies have been slow for gDeactivationTime
// (2 s).  Kinematic bodies always stay awake: an awake kinematic body is what
// wakes the sleeping bodies it touches.
void apply_sleeping(const cfb_world *w, Body *b)
{
    if (b->kind == BODY_STATIC) return;
    btRigidBody *rb = b->rb;
    if (b->kind == BODY_DYNAMIC && w->sleep_linear > 0.0) {
        rb->setSleepingThresholds(w->sleep_linear, w->sleep_angular);
        // setActivationState cannot leave DISABLE_DEACTIVATION; a body that
        // is already ACTIVE_TAG or asleep keeps its state.
        if (rb->getActivationState() == DISABLE_DEACTIVATION) {
            rb->forceActivationState(ACTIVE_TAG);
            rb->setDeactivationTime(0);
        }
    } else {
        rb->forceActivationState(DISABLE_DEACTIVATION);  // also wakes a sleeper
    }
}

// Takes ownership of shape; registers the body and returns its id.
int add_body(cfb_world *w, btCollisionShape *shape, double mass, const btVector3 &inertia,
             const btTransform &xf, BodyKind kind, const btVector3 &kin_v, double friction,
             double restitution)
{
    Body *b = new (std::nothrow) Body();
    if (!b) {
        delete shape;
        set_error("out of memory");
        return -1;
    }
    b->shape = shape;
    b->motion = new btDefaultMotionState(xf);
    btRigidBody::btRigidBodyConstructionInfo ci(mass, b->motion, shape, inertia);
    // No damping of any kind: free flight must follow the integrator exactly.
    ci.m_linearDamping = 0;
    ci.m_angularDamping = 0;
    ci.m_additionalDamping = false;
    // Bullet combines pair coefficients as products (friction clamped to 10).
    ci.m_friction = friction;
    ci.m_restitution = restitution;
    b->rb = new btRigidBody(ci);
    b->kind = kind;
    b->kin_v = kin_v;
    b->kin_w = btVector3(0, 0, 0);
    b->impulse = 0.0;
    b->impulse_static = 0.0;
    b->has_quat = false;

    const int id = static_cast<int>(w->bodies.size());
    b->rb->setUserIndex(id);
    b->rb->setUserIndex2(-1);  // no collision family
    if (kind == BODY_KINEMATIC) {
        b->rb->setCollisionFlags(b->rb->getCollisionFlags() |
                                 btCollisionObject::CF_KINEMATIC_OBJECT);
        b->rb->setLinearVelocity(kin_v);
    }
    b->mesh = NULL;
    apply_sleeping(w, b);

    w->bodies.push_back(b);
    if (kind == BODY_KINEMATIC) w->kinematic.push_back(b);
    w->dyn->addRigidBody(b->rb);
    if (kind == BODY_DYNAMIC) w->n_dynamic++;
    return id;
}

int add_obstacle(cfb_world *w, btCollisionShape *shape, const double center[3],
                 const double velocity[3], double friction, double restitution)
{
    const bool moving = velocity && nonzero3(velocity);
    const btVector3 v = moving ? btVector3(velocity[0], velocity[1], velocity[2])
                               : btVector3(0, 0, 0);
    btTransform xf;
    xf.setIdentity();
    xf.setOrigin(btVector3(center[0], center[1], center[2]));
    return add_body(w, shape, 0.0, btVector3(0, 0, 0), xf,
                    moving ? BODY_KINEMATIC : BODY_STATIC, v, friction, restitution);
}

bool obstacle_args_valid(const cfb_world *w, const double center[3], const double velocity[3],
                         double friction, double restitution)
{
    if (!w) {
        set_error("world is NULL");
        return false;
    }
    if (!center || !finite3(center) || (velocity && !finite3(velocity))) {
        set_error("obstacle centre/velocity missing or non-finite");
        return false;
    }
    return friction_valid(friction, restitution);
}

// Before each sub-step: Bullet derives a kinematic body's velocity from its
// motion-state displacement once per stepSimulation (zero on the first
// call), so restore the prescribed velocity for the contact solver.
void pre_tick(btDynamicsWorld *dw, btScalar)
{
    cfb_world *w = static_cast<cfb_world *>(dw->getWorldUserInfo());
    for (size_t i = 0; i < w->kinematic.size(); ++i) {
        Body *b = w->kinematic[i];
        b->rb->setLinearVelocity(b->kin_v);
        b->rb->setAngularVelocity(b->kin_w);
    }
}

// After each sub-step: collect the solved normal impulses (velocity pass
// only; the split-impulse position pass Bullet uses for penetrations deeper
// than 4 cm applies none), then move the
// kinematic bodies by their velocity over the sub-step (the dynamic bodies
// have just been moved by integrateTransforms).
void post_tick(btDynamicsWorld *dw, btScalar h)
{
    cfb_world *w = static_cast<cfb_world *>(dw->getWorldUserInfo());
    w->ticks++;
    btDispatcher *disp = dw->getDispatcher();
    const int nm = disp->getNumManifolds();
    for (int m = 0; m < nm; ++m) {
        const btPersistentManifold *man = disp->getManifoldByIndexInternal(m);
        double sum = 0.0;
        for (int c = 0; c < man->getNumContacts(); ++c)
            sum += man->getContactPoint(c).getAppliedImpulse();
        if (sum == 0.0) continue;
        const int ids[2] = {man->getBody0()->getUserIndex(), man->getBody1()->getUserIndex()};
        Body *pair[2];
        for (int k = 0; k < 2; ++k)
            pair[k] = ids[k] >= 0 && static_cast<size_t>(ids[k]) < w->bodies.size()
                          ? w->bodies[ids[k]] : nullptr;
        for (int k = 0; k < 2; ++k) {
            if (!pair[k]) continue;
            pair[k]->impulse += sum;
            if (pair[1 - k] && pair[1 - k]->kind == BODY_STATIC)
                pair[k]->impulse_static += sum;
        }
    }
    for (size_t i = 0; i < w->kinematic.size(); ++i) {
        Body *b = w->kinematic[i];
        btTransform next = b->rb->getWorldTransform();
        // Pure translation leaves the basis bit-exact (a quaternion round
        // trip through integrateTransform would not).
        if (b->kin_w.isZero())
            next.setOrigin(next.getOrigin() + b->kin_v * h);
        else
            btTransformUtil::integrateTransform(b->rb->getWorldTransform(), b->kin_v, b->kin_w,
                                                h, next);
        b->motion->setWorldTransform(next);
        b->rb->setWorldTransform(next);
    }
}

// A pair that stops colliding keeps its manifold, whose stale points would
// still reach the solver; release it.
void drop_contacts(cfb_world *w, Body *a, Body *b)
{
    btOverlappingPairCache *cache = w->dyn->getBroadphase()->getOverlappingPairCache();
    btBroadphasePair *pair =
        cache->findPair(a->rb->getBroadphaseHandle(), b->rb->getBroadphaseHandle());
    if (pair) cache->cleanOverlappingPair(*pair, w->dispatcher);
}

void destroy_body(cfb_world *w, Body *b)
{
    w->dyn->removeRigidBody(b->rb);
    delete b->rb;
    delete b->motion;
    delete b->shape;  // before its children and its mesh
    for (size_t i = 0; i < b->children.size(); ++i) delete b->children[i];
    delete b->mesh;
    delete b;
}

bool mass_props_valid(double mass, const double inertia[3])
{
    if (!std::isfinite(mass) || !(mass > 0.0)) {
        set_error("mass must be finite and > 0 (got %g)", mass);
        return false;
    }
    if (!inertia || !finite3(inertia) || !(inertia[0] > 0.0) || !(inertia[1] > 0.0) ||
        !(inertia[2] > 0.0)) {
        set_error("principal moments must be finite and > 0");
        return false;
    }
    return true;
}

// Hull vertices of pts[0..n) as the caller's own points: btConvexHullComputer
// works on integer coordinates, and its `vertices` are those rounded back to
// doubles (off by ~1e-9 of the extent unless the input happens to be on its
// grid); original_vertex_index names the input point each one came from.
void hull_vertices(const btConvexHullComputer &hull, const double *pts, int n,
                   btAlignedObjectArray<btVector3> &out)
{
    const int nv = hull.vertices.size();
    out.resize(nv);
    for (int i = 0; i < nv; ++i) {
        const int k = i < hull.original_vertex_index.size() ? hull.original_vertex_index[i] : -1;
        out[i] = (k >= 0 && k < n) ? btVector3(pts[3 * k], pts[3 * k + 1], pts[3 * k + 2])
                                   : hull.vertices[i];
    }
}

// Convex hull shape over the hull vertices of pts[0..n) (support queries are
// linear in the vertex count, and fragments may come with thousands of
// surface nodes).  NULL, with *nv set, when the hull has under 4 vertices.
btConvexHullShape *hull_shape(const double *pts, int n, double margin, int *nv)
{
    btConvexHullComputer hull;
    hull.compute(pts, 3 * static_cast<int>(sizeof(double)), n, 0, 0);
    *nv = hull.vertices.size();
    if (*nv < 4) return NULL;
    btAlignedObjectArray<btVector3> v;
    hull_vertices(hull, pts, n, v);
    btConvexHullShape *shape = new btConvexHullShape(&v[0][0], *nv, sizeof(btVector3));
    shape->setMargin(margin);
    shape->recalcLocalAabb();  // the cached box was built with the default margin
    return shape;
}

// Registers a dynamic body of the given shape (owned) at state s.
int add_dynamic(cfb_world *w, btCollisionShape *shape, double mass, const double inertia[3],
                const cfb_state *s, double friction, double restitution)
{
    double q[4];
    unit_quat(s->quat, q);
    const btTransform xf = state_transform(q, s->pos);
    // The body frame is the principal frame, so the given moments are the
    // local inertia (not Bullet's estimate from the shape's bounding box).
    const int id = add_body(w, shape, mass, btVector3(inertia[0], inertia[1], inertia[2]), xf,
                            BODY_DYNAMIC, btVector3(0, 0, 0), friction, restitution);
    if (id < 0) return -1;
    Body *b = w->bodies[id];
    b->rb->setLinearVelocity(btVector3(s->v[0], s->v[1], s->v[2]));
    b->rb->setAngularVelocity(btVector3(s->w[0], s->w[1], s->w[2]));
    b->rb->setInterpolationLinearVelocity(b->rb->getLinearVelocity());
    b->rb->setInterpolationAngularVelocity(b->rb->getAngularVelocity());
    remember_quat(b, q);
    return id;
}

// Smallest world box around a shape, margin included: convex shapes from
// their support points along the world axes (hull vertices + margin, exact
// under rotation, where Bullet's own getAabb rotates a cached local box),
// compounds from their children, others (plane, triangle mesh) from Bullet.
void shape_aabb(const btCollisionShape *shape, const btTransform &xf, btVector3 &lo,
                btVector3 &hi)
{
    if (shape->isCompound()) {
        const btCompoundShape *c = static_cast<const btCompoundShape *>(shape);
        lo.setValue(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
        hi.setValue(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
        for (int i = 0; i < c->getNumChildShapes(); ++i) {
            btVector3 clo, chi;
            shape_aabb(c->getChildShape(i), xf * c->getChildTransform(i), clo, chi);
            lo.setMin(clo);
            hi.setMax(chi);
        }
        return;
    }
    if (shape->isConvex()) {
        const btConvexShape *cs = static_cast<const btConvexShape *>(shape);
        const btScalar m = cs->getMargin();
        const btMatrix3x3 &R = xf.getBasis();
        double l[3], h[3];
        for (int i = 0; i < 3; ++i) {
            // Local direction R^T e_i is row i of R.
            const btVector3 up = xf(cs->localGetSupportingVertexWithoutMargin(R.getRow(i)));
            const btVector3 dn = xf(cs->localGetSupportingVertexWithoutMargin(-R.getRow(i)));
            h[i] = up[i] + m;
            l[i] = dn[i] - m;
        }
        lo.setValue(l[0], l[1], l[2]);
        hi.setValue(h[0], h[1], h[2]);
        return;
    }
    shape->getAabb(xf, lo, hi);
}

// Collects the deepest contact of a contactPairTest.
struct DepthCallback : public btCollisionWorld::ContactResultCallback {
    double min_distance;
    DepthCallback() : min_distance(0.0) {}
    btScalar addSingleResult(btManifoldPoint &cp, const btCollisionObjectWrapper *,
                             int, int, const btCollisionObjectWrapper *, int, int) override
    {
        if (cp.getDistance() < min_distance) min_distance = cp.getDistance();
        return 0;
    }
};

}  // namespace

extern "C" {

/* Bullet's allocations go through these two, so that the run summary can
 * say how much memory the Bullet world takes.  malloc_usable_size keeps
 * the count right for blocks allocated before the hook was set. */
static long long bullet_bytes;

// Bullet does not check its allocations (btPoolAllocator memsets what it
// got): a failed one throws instead, and the entry points that allocate
// turn that into an error (cfb_last_error: "out of memory").
static void *counted_alloc(size_t n)
{
    void *p = malloc(n);
    if (!p)
        throw std::bad_alloc();
    __atomic_add_fetch(&bullet_bytes, (long long)malloc_usable_size(p), __ATOMIC_RELAXED);
    return p;
}

static void counted_free(void *p)
{
    if (!p)
        return;
    __atomic_sub_fetch(&bullet_bytes, (long long)malloc_usable_size(p), __ATOMIC_RELAXED);
    free(p);
}

static const bool hook_set = (btAlignedAllocSetCustom(counted_alloc, counted_free), true);

unsigned long long cfb_allocated_bytes(void)
{
    (void)hook_set;
    long long n = __atomic_load_n(&bullet_bytes, __ATOMIC_RELAXED);
    return n > 0 ? (unsigned long long)n : 0;
}

cfb_world *cfb_world_create(const double gravity[3])
{
    if (!gravity || !finite3(gravity)) {
        set_error("gravity missing or non-finite");
        return NULL;
    }
    cfb_world *w = new (std::nothrow) cfb_world();
    if (!w) {
        set_error("out of memory");
        return NULL;
    }
    try {
        w->config = new btDefaultCollisionConfiguration();
        w->dispatcher = new FamilyDispatcher(w->config);
        w->broadphase = new btDbvtBroadphase();
        w->solver = new btSequentialImpulseConstraintSolver();
        w->dyn = new StepWorld(w->dispatcher, w->broadphase, w->solver, w->config);
        w->filter = new FamilyFilter();
        w->dyn->getPairCache()->setOverlapFilterCallback(w->filter);
    } catch (const std::bad_alloc &) {
        set_error("out of memory building the Bullet world (its pools need a few MB)");
        return NULL; // what was built is lost: the run ends here
    }
    w->dyn->setGravity(btVector3(gravity[0], gravity[1], gravity[2]));
    // Motion states show the state at the end of the last sub-step, not one
    // sub-step behind.
    w->dyn->setLatencyMotionStateInterpolation(false);
    // Restitution needs a contact point to appear when the bodies touch:
    // Bullet creates one up to gContactBreakingThreshold x the shape's
    // size ahead (2% by default), and the solver's speculative treatment of
    // that gap eats the restitution over the sub-steps of the approach.
    // 0.1% keeps the gap below one sub-step's travel at impact speeds.
    gContactBreakingThreshold = 1e-3;
    w->dyn->getSolverInfo().m_restingContactRestitutionThreshold = 1 << 30;
    // CCD (cfb_set_ccd) ignores a time of impact unless the sub-step's
    // motion along the contact normal exceeds this (4 cm by default): a 1 cm
    // fragment moving 4 cm per sub-step would tunnel through a thin wall.
    w->dyn->getDispatchInfo().m_allowedCcdPenetration = 0;
    w->dyn->setInternalTickCallback(pre_tick, w, true);
    w->dyn->setInternalTickCallback(post_tick, w, false);
    w->n_dynamic = 0;
    w->ticks = 0;
    w->sleep_linear = 0.0;
    w->sleep_angular = 0.0;
    w->out_of_memory = false;
    return w;
}

void cfb_world_destroy(cfb_world *w)
{
    if (!w) return;
    for (size_t i = 0; i < w->bodies.size(); ++i)
        if (w->bodies[i]) destroy_body(w, w->bodies[i]);
    delete w->dyn;
    delete w->solver;
    delete w->broadphase;
    delete w->filter;
    delete w->dispatcher;
    delete w->config;
    delete w;
}

// A plane obstacle whose bounding box is the half-space behind it and the
// contact breaking threshold in front, where its normal lies along an axis
// (other normals keep the box of all space).  btStaticPlaneShape's box
// holds all of space: the broadphase paired every body with the floor, and
// each hull of every compound went through the plane test at every step,
// pieces in flight a metre above it too; on the 15,040-tet plaster drop,
// with its hundreds of pieces, Bullet's step took a median 7.3 s of a
// ~65 s run over seeds 1-5, now 2.4 s.  A hull within a body's breaking
// threshold of the plane (gContactBreakingThreshold, 1 mm here, times its
// bounding radius in metres) still meets the plane test, which makes the
// same contacts as before, speculative ones included, for bodies up to
// 1 m in radius.  The pieces' hulls now get their manifolds with the plane
// as they come near it, so the order of a body's manifolds, and the last
// bits of the sequential impulses, move.
class HalfSpacePlane : public btStaticPlaneShape {
public:
    HalfSpacePlane(const btVector3 &n, btScalar c) : btStaticPlaneShape(n, c) {}
    void getAabb(const btTransform &t, btVector3 &aabbMin, btVector3 &aabbMax) const override
    {
        btStaticPlaneShape::getAabb(t, aabbMin, aabbMax);
        const btVector3 n = t.getBasis() * getPlaneNormal();
        const btScalar c = getPlaneConstant() + n.dot(t.getOrigin());
        for (int k = 0; k < 3; k++) {
            const int j = (k + 1) % 3, l = (k + 2) % 3;
            if (n[j] != 0 || n[l] != 0) continue;
            if (n[k] > 0) aabbMax[k] = c / n[k] + gContactBreakingThreshold;  // x_k <= c
            if (n[k] < 0) aabbMin[k] = c / n[k] - gContactBreakingThreshold;  // x_k >= -c
        }
    }
};

static int add_plane_unguarded(cfb_world *w, const double point[3], const double normal[3],
                               double friction, double restitution)
{
    if (!obstacle_args_valid(w, point, NULL, friction, restitution)) return -1;
    if (!normal || !finite3(normal) || !nonzero3(normal)) {
        set_error("plane normal missing, zero or non-finite");
        return -1;
    }
    btVector3 n(normal[0], normal[1], normal[2]);
    n.normalize();
    const btScalar c = n.dot(btVector3(point[0], point[1], point[2]));
    btTransform xf;
    xf.setIdentity();
    return add_body(w, new HalfSpacePlane(n, c), 0.0, btVector3(0, 0, 0), xf, BODY_STATIC,
                    btVector3(0, 0, 0), friction, restitution);
}

static int add_sphere_unguarded(cfb_world *w, const double center[3], double radius,
                                const double velocity[3], double friction, double restitution)
{
    if (!obstacle_args_valid(w, center, velocity, friction, restitution)) return -1;
    if (!std::isfinite(radius) || !(radius > 0.0)) {
        set_error("sphere radius must be finite and > 0");
        return -1;
    }
    return add_obstacle(w, new btSphereShape(radius), center, velocity, friction, restitution);
}

static int add_box_unguarded(cfb_world *w, const double center[3], const double half_extents[3],
                             const double velocity[3], double friction, double restitution)
{
    if (!obstacle_args_valid(w, center, velocity, friction, restitution)) return -1;
    if (!half_extents || !finite3(half_extents) || !(half_extents[0] > 0.0) ||
        !(half_extents[1] > 0.0) || !(half_extents[2] > 0.0)) {
        set_error("box half extents must be finite and > 0");
        return -1;
    }
    btBoxShape *box = new btBoxShape(btVector3(half_extents[0], half_extents[1], half_extents[2]));
    // btBoxShape keeps its outer size and rounds corners by the margin; keep
    // the rounding small relative to thin boxes.
    const double hmin = std::fmin(half_extents[0], std::fmin(half_extents[1], half_extents[2]));
    if (box->getMargin() > 0.1 * hmin) box->setMargin(0.1 * hmin);
    return add_obstacle(w, box, center, velocity, friction, restitution);
}

static int add_hull_body_unguarded(cfb_world *w, double mass, const double inertia[3],
                                   const double *pts, int n, double margin, const cfb_state *s,
                                   double friction, double restitution)
{
    if (!pts || n < 4) {
        set_error("a hull needs at least 4 points (got %d)", pts ? n : 0);
        return -1;
    }
    const int start[2] = {0, n};  // one hull: a plain convex hull shape
    return cfb_add_compound_body(w, mass, inertia, pts, start, 1, margin, s, friction, restitution);
}

static int convex_hull_unguarded(const double *pts, int n, double *out, double *volume)
{
    if (!pts || n < 1) {
        set_error("convex hull needs at least 1 point (got %d)", pts ? n : 0);
        return -1;
    }
    for (int i = 0; i < n; ++i) {
        if (!finite3(pts + 3 * i)) {
            set_error("hull point %d is non-finite", i);
            return -1;
        }
    }
    btConvexHullComputer hull;
    hull.compute(pts, 3 * static_cast<int>(sizeof(double)), n, 0, 0);
    const int nv = hull.vertices.size();
    btAlignedObjectArray<btVector3> v;
    hull_vertices(hull, pts, n, v);
    if (out)
        for (int i = 0; i < nv; ++i)
            for (int c = 0; c < 3; ++c) out[3 * i + c] = v[i][c];
    if (volume) {
        // Divergence theorem: V = 1/6 sum over faces of fan triangles
        // (a - o) . ((b - o) x (c - o)), o the first vertex (less round-off
        // than the origin).
        double six_v = 0.0;
        if (nv >= 4) {
            const btVector3 &o = v[0];
            for (int f = 0; f < hull.faces.size(); ++f) {
                const btConvexHullComputer::Edge *e0 = &hull.edges[hull.faces[f]];
                const btVector3 a = v[e0->getSourceVertex()] - o;
                const btConvexHullComputer::Edge *e = e0->getNextEdgeOfFace();
                btVector3 b = v[e->getSourceVertex()] - o;
                for (e = e->getNextEdgeOfFace(); e != e0; e = e->getNextEdgeOfFace()) {
                    const btVector3 c = v[e->getSourceVertex()] - o;
                    six_v += a.dot(b.cross(c));
                    b = c;
                }
            }
        }
        // A flat hull (both sides of one polygon) sums to round-off.
        btVector3 lo = nv > 0 ? v[0] : btVector3(0, 0, 0), hi = lo;
        for (int i = 1; i < nv; ++i) {
            lo.setMin(v[i]);
            hi.setMax(v[i]);
        }
        const double L = (hi - lo).length();
        const double vol = std::fabs(six_v) / 6.0;
        *volume = vol <= 1e-12 * L * L * L ? 0.0 : vol;
    }
    return nv;
}

static int add_compound_body_unguarded(cfb_world *w, double mass, const double inertia[3],
                                       const double *pts, const int *start, int n_hulls,
                                       double margin, const cfb_state *s, double friction,
                                       double restitution)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    if (!mass_props_valid(mass, inertia)) return -1;
    if (!pts || !start || n_hulls < 1) {
        set_error("compound needs points, hull starts and at least 1 hull (got %d)", n_hulls);
        return -1;
    }
    if (start[0] != 0) {
        set_error("hull starts must begin at 0 (got %d)", start[0]);
        return -1;
    }
    for (int h = 0; h < n_hulls; ++h) {
        if (start[h + 1] - start[h] < 4) {
            set_error("hull %d needs at least 4 points (got %d)", h, start[h + 1] - start[h]);
            return -1;
        }
    }
    for (int i = 0; i < start[n_hulls]; ++i) {
        if (!finite3(pts + 3 * i)) {
            set_error("hull point %d is non-finite", i);
            return -1;
        }
    }
    if (!std::isfinite(margin) || margin < 0.0) {
        set_error("margin must be finite and >= 0");
        return -1;
    }
    if (!state_valid(s) || !friction_valid(friction, restitution)) return -1;

    std::vector<btCollisionShape *> children;
    for (int h = 0; h < n_hulls; ++h) {
        int nv = 0;
        btConvexHullShape *c =
            hull_shape(pts + 3 * start[h], start[h + 1] - start[h], margin, &nv);
        if (!c) {
            for (size_t i = 0; i < children.size(); ++i) delete children[i];
            set_error("hull %d is degenerate (%d hull vertices)", h, nv);
            return -1;
        }
        children.push_back(c);
    }
    if (n_hulls == 1) return add_dynamic(w, children[0], mass, inertia, s, friction, restitution);

    // The points are already in the principal frame: identity child
    // transforms.  The compound's own margin stays 0 (it only pads its box).
    btCompoundShape *compound = new btCompoundShape(true, n_hulls);
    btTransform id_xf;
    id_xf.setIdentity();
    for (int h = 0; h < n_hulls; ++h) compound->addChildShape(id_xf, children[h]);
    const int id = add_dynamic(w, compound, mass, inertia, s, friction, restitution);
    if (id < 0) {
        for (size_t i = 0; i < children.size(); ++i) delete children[i];
        return -1;
    }
    w->bodies[id]->children.swap(children);
    return id;
}

static int add_sphere_body_unguarded(cfb_world *w, double mass, const double inertia[3],
                                     double radius, const cfb_state *s, double friction,
                                     double restitution)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    if (!mass_props_valid(mass, inertia)) return -1;
    if (!std::isfinite(radius) || !(radius > 0.0)) {
        set_error("sphere radius must be finite and > 0 (got %g)", radius);
        return -1;
    }
    if (!state_valid(s) || !friction_valid(friction, restitution)) return -1;
    return add_dynamic(w, new btSphereShape(radius), mass, inertia, s, friction, restitution);
}

static int add_trimesh_unguarded(cfb_world *w, const double *verts, int nv, const int *tris, int nt,
                                 double friction, double restitution)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    if (!verts || nv < 3 || !tris || nt < 1) {
        set_error("triangle mesh needs >= 3 vertices and >= 1 triangle (got %d, %d)",
                  verts ? nv : 0, tris ? nt : 0);
        return -1;
    }
    for (int i = 0; i < nv; ++i) {
        if (!finite3(verts + 3 * i)) {
            set_error("mesh vertex %d is non-finite", i);
            return -1;
        }
    }
    for (int t = 0; t < nt; ++t) {
        const int *v = tris + 3 * t;
        for (int k = 0; k < 3; ++k) {
            if (v[k] < 0 || v[k] >= nv) {
                set_error("triangle %d: vertex index %d out of range [0, %d)", t, v[k], nv);
                return -1;
            }
        }
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            set_error("triangle %d repeats a vertex", t);
            return -1;
        }
    }
    if (!friction_valid(friction, restitution)) return -1;

    // The body owns copies of the arrays: Bullet keeps pointers into them.
    btTriangleIndexVertexArray *mesh = new btTriangleIndexVertexArray();
    std::vector<btScalar> vcopy(verts, verts + 3 * static_cast<size_t>(nv));
    std::vector<int> tcopy(tris, tris + 3 * static_cast<size_t>(nt));
    btIndexedMesh part;
    part.m_numTriangles = nt;
    part.m_triangleIndexBase = reinterpret_cast<const unsigned char *>(&tcopy[0]);
    part.m_triangleIndexStride = 3 * static_cast<int>(sizeof(int));
    part.m_numVertices = nv;
    part.m_vertexBase = reinterpret_cast<const unsigned char *>(&vcopy[0]);
    part.m_vertexStride = 3 * static_cast<int>(sizeof(btScalar));
    part.m_indexType = PHY_INTEGER;
    part.m_vertexType = PHY_DOUBLE;
    mesh->addIndexedMesh(part, PHY_INTEGER);
    btBvhTriangleMeshShape *shape = new btBvhTriangleMeshShape(mesh, true, true);

    btTransform xf;
    xf.setIdentity();
    const int id = add_body(w, shape, 0.0, btVector3(0, 0, 0), xf, BODY_STATIC,
                            btVector3(0, 0, 0), friction, restitution);
    if (id < 0) {
        delete mesh;
        return -1;
    }
    Body *b = w->bodies[id];
    b->mesh = mesh;
    // Swapping moves the buffers without copying: the pointers stay valid.
    b->mesh_verts.swap(vcopy);
    b->mesh_tris.swap(tcopy);
    return id;
}

static int set_ccd_unguarded(cfb_world *w, int id, double motion_threshold, double swept_radius)
{
    Body *b = lookup(w, id);
    if (!b) return -1;
    if (b->kind != BODY_DYNAMIC) {
        set_error("body %d is not dynamic", id);
        return -1;
    }
    if (!std::isfinite(motion_threshold) || !std::isfinite(swept_radius) ||
        motion_threshold < 0.0 || swept_radius < 0.0 ||
        (motion_threshold > 0.0) != (swept_radius > 0.0)) {
        set_error("CCD threshold and radius must both be > 0, or both 0 (got %g, %g)",
                  motion_threshold, swept_radius);
        return -1;
    }
    if (motion_threshold > 0.0 && !b->rb->getCollisionShape()->isConvex()) {
        set_error("body %d is a compound: Bullet's CCD sweeps convex shapes only", id);
        return -1;
    }
    b->rb->setCcdMotionThreshold(motion_threshold);
    b->rb->setCcdSweptSphereRadius(swept_radius);
    return 0;
}

int cfb_set_sleeping(cfb_world *w, double linear, double angular)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    if (!std::isfinite(linear) || !std::isfinite(angular) || linear < 0.0 || angular < 0.0 ||
        (linear > 0.0) != (angular > 0.0)) {
        set_error("sleeping thresholds must both be > 0, or both 0 (got %g, %g)", linear,
                  angular);
        return -1;
    }
    w->sleep_linear = linear;
    w->sleep_angular = angular;
    for (size_t i = 0; i < w->bodies.size(); ++i)
        if (w->bodies[i]) apply_sleeping(w, w->bodies[i]);
    return 0;
}

int cfb_is_sleeping(const cfb_world *w, int id)
{
    const Body *b = lookup(w, id);
    if (!b) return -1;
    // Bullet marks static bodies ISLAND_SLEEPING; only dynamic ones sleep.
    if (b->kind != BODY_DYNAMIC) return 0;
    return b->rb->getActivationState() == ISLAND_SLEEPING ? 1 : 0;
}

int cfb_apply_impulse(cfb_world *w, int id, const double J[3], const double p[3])
{
    Body *b = lookup(w, id);
    if (!b) return -1;
    if (b->kind != BODY_DYNAMIC) {
        set_error("body %d is not dynamic", id);
        return -1;
    }
    if (!J || !p || !finite3(J) || !finite3(p)) {
        set_error("impulse or point missing or non-finite");
        return -1;
    }
    btRigidBody *rb = b->rb;
    const btVector3 r = btVector3(p[0], p[1], p[2]) - rb->getCenterOfMassPosition();
    rb->applyImpulse(btVector3(J[0], J[1], J[2]), r);
    rb->setInterpolationLinearVelocity(rb->getLinearVelocity());
    rb->setInterpolationAngularVelocity(rb->getAngularVelocity());
    rb->activate(true);
    return 0;
}

int cfb_get_aabb(const cfb_world *w, int id, double lo[3], double hi[3])
{
    const Body *b = lookup(w, id);
    if (!b) return -1;
    if (!lo || !hi) {
        set_error("box output is NULL");
        return -1;
    }
    btVector3 l, h;
    shape_aabb(b->rb->getCollisionShape(), b->rb->getWorldTransform(), l, h);
    for (int i = 0; i < 3; ++i) {
        lo[i] = l[i];
        hi[i] = h[i];
    }
    return 0;
}

static double pair_penetration_unguarded(cfb_world *w, int a, int b)
{
    Body *ba = lookup(w, a);
    if (!ba) return -1.0;
    Body *bb = lookup(w, b);
    if (!bb) return -1.0;
    if (a == b) {
        set_error("penetration of body %d with itself", a);
        return -1.0;
    }
    // contactPairTest goes straight to the pair's collision algorithm: it
    // asks neither the dispatcher's needsCollision (collision families) nor
    // checkCollideWith (cfb_ignore_pair), so excluded pairs are measured too.
    DepthCallback cb;
    w->dyn->contactPairTest(ba->rb, bb->rb, cb);
    return cb.min_distance < 0.0 ? -cb.min_distance : 0.0;
}

static void unignore_pair_unguarded(cfb_world *w, int a, int b)
{
    Body *ba = lookup(w, a);
    if (!ba) return;
    Body *bb = lookup(w, b);
    if (!bb) return;
    if (a == b) {
        set_error("cannot unignore a body against itself (%d)", a);
        return;
    }
    bool found = false;
    for (size_t k = 0; k < ba->ignored.size(); ++k) {
        if (ba->ignored[k] == b) {
            ba->ignored.erase(ba->ignored.begin() + static_cast<std::ptrdiff_t>(k));
            found = true;
            break;
        }
    }
    if (!found) return;  // not ignored: nothing to undo
    for (size_t k = 0; k < bb->ignored.size(); ++k) {
        if (bb->ignored[k] == a) {
            bb->ignored.erase(bb->ignored.begin() + static_cast<std::ptrdiff_t>(k));
            break;
        }
    }
    ba->rb->setIgnoreCollisionCheck(bb->rb, false);
    bb->rb->setIgnoreCollisionCheck(ba->rb, false);
    // Two sleeping bodies are not tested against each other: wake them so
    // an overlap shows up at the next step.
    if (ba->kind == BODY_DYNAMIC) ba->rb->activate(true);
    if (bb->kind == BODY_DYNAMIC) bb->rb->activate(true);
}

static void remove_body_unguarded(cfb_world *w, int id)
{
    Body *b = lookup(w, id);
    if (!b) return;
    // Others keep a pointer to this body in their ignore lists; drop it so a
    // later body allocated at the same address is not ignored by mistake.
    for (size_t k = 0; k < b->ignored.size(); ++k) {
        Body *o = w->bodies[b->ignored[k]];
        if (!o) continue;
        o->rb->setIgnoreCollisionCheck(b->rb, false);
        for (size_t j = 0; j < o->ignored.size(); ++j) {
            if (o->ignored[j] == id) {
                o->ignored.erase(o->ignored.begin() + static_cast<std::ptrdiff_t>(j));
                break;
            }
        }
    }
    if (b->kind == BODY_DYNAMIC) w->n_dynamic--;
    for (size_t k = 0; k < w->kinematic.size(); ++k) {
        if (w->kinematic[k] == b) {
            w->kinematic.erase(w->kinematic.begin() + static_cast<std::ptrdiff_t>(k));
            break;
        }
    }
    destroy_body(w, b);
    w->bodies[id] = NULL;
}

void cfb_get_state(const cfb_world *w, int id, cfb_state *s)
{
    const Body *b = lookup(w, id);
    if (!b) return;
    if (!s) {
        set_error("state is NULL");
        return;
    }
    const btTransform &xf = b->rb->getCenterOfMassTransform();
    const btVector3 &p = xf.getOrigin();
    const btVector3 &v = b->rb->getLinearVelocity();
    const btVector3 &om = b->rb->getAngularVelocity();
    for (int i = 0; i < 3; ++i) {
        s->pos[i] = p[i];
        s->v[i] = v[i];
        s->w[i] = om[i];
    }
    if (b->has_quat && xf.getBasis() == b->quat_basis) {
        for (int i = 0; i < 4; ++i) s->quat[i] = b->quat[i];
        return;
    }
    btQuaternion q;
    xf.getBasis().getRotation(q);
    const double sgn = q.w() < 0 ? -1.0 : 1.0;  // one representative: w >= 0
    s->quat[0] = sgn * q.w();
    s->quat[1] = sgn * q.x();
    s->quat[2] = sgn * q.y();
    s->quat[3] = sgn * q.z();
}

void cfb_set_state(cfb_world *w, int id, const cfb_state *s)
{
    Body *b = lookup(w, id);
    if (!b) return;
    if (!state_valid(s)) return;
    if (b->kind == BODY_STATIC) {
        set_error("body %d is static", id);
        return;
    }
    double q[4];
    unit_quat(s->quat, q);
    const btTransform xf = state_transform(q, s->pos);
    const btVector3 v(s->v[0], s->v[1], s->v[2]);
    const btVector3 om(s->w[0], s->w[1], s->w[2]);
    btRigidBody *rb = b->rb;
    if (b->kind == BODY_KINEMATIC) {
        b->kin_v = v;
        b->kin_w = om;
        rb->setWorldTransform(xf);
    } else {
        rb->setCenterOfMassTransform(xf);  // also refreshes the world inertia
    }
    rb->setInterpolationWorldTransform(xf);
    rb->setLinearVelocity(v);
    rb->setAngularVelocity(om);
    rb->setInterpolationLinearVelocity(v);
    rb->setInterpolationAngularVelocity(om);
    rb->clearForces();
    b->motion->setWorldTransform(xf);
    rb->activate(true);
    w->dyn->updateSingleAabb(rb);
    remember_quat(b, q);
}

static void ignore_pair_unguarded(cfb_world *w, int a, int b)
{
    Body *ba = lookup(w, a);
    if (!ba) return;
    Body *bb = lookup(w, b);
    if (!bb) return;
    if (a == b) {
        set_error("cannot ignore a body against itself (%d)", a);
        return;
    }
    for (size_t k = 0; k < ba->ignored.size(); ++k)
        if (ba->ignored[k] == b) return;  // Bullet does not check duplicates
    ba->ignored.push_back(b);
    bb->ignored.push_back(a);
    ba->rb->setIgnoreCollisionCheck(bb->rb, true);
    bb->rb->setIgnoreCollisionCheck(ba->rb, true);
    drop_contacts(w, ba, bb);
}

static int set_family_unguarded(cfb_world *w, int id, int family)
{
    Body *b = lookup(w, id);
    if (!b) return -1;
    if (family < -1) {
        set_error("family must be >= 0, or -1 for none (got %d)", family);
        return -1;
    }
    b->rb->setUserIndex2(family);
    // Its pairs were made (or refused) under the old family: a new proxy
    // takes the overlaps again through the filter, and the old one's
    // pairs go with their contacts.
    w->dyn->refreshBroadphaseProxy(b->rb);
    return 0;
}

static int step_unguarded(cfb_world *w, double dt, int substeps)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    if (w->out_of_memory) {
        set_error("out of memory inside Bullet (in an earlier call)");
        return -1;
    }
    if (!std::isfinite(dt) || !(dt > 0.0) || substeps < 1) {
        set_error("cfb_step needs dt > 0 and substeps >= 1 (got %g, %d)", dt, substeps);
        return -1;
    }
    const double h = dt / substeps;
    // stepSimulation runs int(accumulated/h) sub-steps; with dt/h only
    // approximately equal to substeps that may round down to substeps-1.
    // Nudge the interval up by ulps so the quotient is exactly substeps, and
    // clear the accumulator around the call so nothing carries over.
    double t = dt;
    while (static_cast<int>(t / h) < substeps)
        t = std::nextafter(t, std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < w->bodies.size(); ++i)
        if (w->bodies[i]) w->bodies[i]->impulse = w->bodies[i]->impulse_static = 0.0;
    w->ticks = 0;
    w->dyn->reset_local_time();
    w->dyn->stepSimulation(t, substeps, h);
    w->dyn->reset_local_time();
    if (w->ticks != substeps) {
        set_error("ran %d sub-steps instead of %d", w->ticks, substeps);
        return -1;
    }
    return 0;
}

double cfb_contact_impulse(const cfb_world *w, int id)
{
    const Body *b = lookup(w, id);
    return b ? b->impulse : -1.0;
}

double cfb_contact_impulse_static(const cfb_world *w, int id)
{
    const Body *b = lookup(w, id);
    return b ? b->impulse_static : -1.0;
}

int cfb_body_count(const cfb_world *w)
{
    if (!w) {
        set_error("world is NULL");
        return -1;
    }
    return w->n_dynamic;
}

const char *cfb_last_error(void) { return g_error; }

}  // extern "C"

// The entry points that make Bullet allocate: out of memory (counted_alloc
// throws) is an error return (cfb_last_error: "out of memory inside
// Bullet"), not a crash, and marks the world so that the next cfb_step
// fails too (a call cut short leaves the world unusable; the caller ends
// the run).  The void ones have only that mark.
template <typename R, typename F> static R marked(cfb_world *w, R fail, F f)
{
    try {
        return f();
    } catch (const std::bad_alloc &) {
        set_error("out of memory inside Bullet");
        if (w)
            w->out_of_memory = true;
        return fail;
    }
}

int cfb_add_plane(cfb_world *w, const double point[3], const double normal[3], double friction,
                  double restitution)
{
    return marked(w, -1, [&] {
        return add_plane_unguarded(w, point, normal, friction, restitution);
    });
}

int cfb_add_sphere(cfb_world *w, const double center[3], double radius,
                   const double velocity[3], double friction, double restitution)
{
    return marked(w, -1, [&] {
        return add_sphere_unguarded(w, center, radius, velocity, friction, restitution);
    });
}

int cfb_add_box(cfb_world *w, const double center[3], const double half_extents[3],
                const double velocity[3], double friction, double restitution)
{
    return marked(w, -1, [&] {
        return add_box_unguarded(w, center, half_extents, velocity, friction, restitution);
    });
}

int cfb_add_hull_body(cfb_world *w, double mass, const double inertia[3], const double *pts,
                      int n, double margin, const cfb_state *s, double friction,
                      double restitution)
{
    return marked(w, -1, [&] {
        return add_hull_body_unguarded(w, mass, inertia, pts, n, margin, s, friction, restitution);
    });
}

int cfb_convex_hull(const double *pts, int n, double *out, double *volume)
{
    return marked(nullptr, -1, [&] { return convex_hull_unguarded(pts, n, out, volume); });
}

int cfb_add_compound_body(cfb_world *w, double mass, const double inertia[3], const double *pts,
                          const int *start, int n_hulls, double margin, const cfb_state *s,
                          double friction, double restitution)
{
    return marked(w, -1, [&] {
        return add_compound_body_unguarded(w, mass, inertia, pts, start, n_hulls, margin, s,
                                           friction, restitution);
    });
}

int cfb_add_sphere_body(cfb_world *w, double mass, const double inertia[3], double radius,
                        const cfb_state *s, double friction, double restitution)
{
    return marked(w, -1, [&] {
        return add_sphere_body_unguarded(w, mass, inertia, radius, s, friction, restitution);
    });
}

int cfb_add_trimesh(cfb_world *w, const double *verts, int nv, const int *tris, int nt,
                    double friction, double restitution)
{
    return marked(w, -1, [&] {
        return add_trimesh_unguarded(w, verts, nv, tris, nt, friction, restitution);
    });
}

int cfb_step(cfb_world *w, double dt, int substeps)
{
    return marked(w, -1, [&] { return step_unguarded(w, dt, substeps); });
}

int cfb_set_family(cfb_world *w, int id, int family)
{
    return marked(w, -1, [&] { return set_family_unguarded(w, id, family); });
}

int cfb_set_ccd(cfb_world *w, int id, double motion_threshold, double swept_radius)
{
    return marked(w, -1, [&] { return set_ccd_unguarded(w, id, motion_threshold, swept_radius); });
}

double cfb_pair_penetration(cfb_world *w, int a, int b)
{
    return marked(w, -1.0, [&] { return pair_penetration_unguarded(w, a, b); });
}

void cfb_unignore_pair(cfb_world *w, int a, int b)
{
    marked(w, 0, [&] { return unignore_pair_unguarded(w, a, b), 0; });
}

void cfb_remove_body(cfb_world *w, int id)
{
    marked(w, 0, [&] { return remove_body_unguarded(w, id), 0; });
}

void cfb_ignore_pair(cfb_world *w, int a, int b)
{
    marked(w, 0, [&] { return ignore_pair_unguarded(w, a, b), 0; });
}
