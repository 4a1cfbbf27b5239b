// cohfrac_softbody_peer: the btSoftBody peer for `cohfrac bench --peer`: the
// same tet mesh, dt and iteration count, one link per unique edge, a ground.
// It steps Bullet's position-based soft body, placed as our scene places the
// mesh, and prints per-step wall and CPU times on its last line.
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <new>
#include <string>
#include <vector>

static double now_s(clockid_t id)
{
  struct timespec ts;
  clock_gettime(id, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static bool read_file(const std::string &path, std::string &out)
{
  FILE *f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  bool ok = !std::ferror(f);
  std::fclose(f);
  return ok;
}

// The data lines of a TetGen file: '#' starts a comment, blank lines skipped.
static std::vector<const char *> data_lines(std::string &text)
{
  std::vector<const char *> lines;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const char *hash = (const char *)std::memchr(&text[pos], '#', end - pos);  // this line only
    size_t cut = hash ? (size_t)(hash - &text[0]) : end;
    if (cut < text.size()) text[cut] = '\0';  // terminate the line for sscanf
    if (std::strspn(&text[pos], " \t\r") < cut - pos) lines.push_back(&text[pos]);
    pos = end + 1;
  }
  return lines;
}

static bool parse_num(const char *s, double &v)
{
  char *end;
  v = std::strtod(s, &end);
  return end != s && *end == '\0' && std::isfinite(v);
}

static int bad(const char *what)
{
  std::fprintf(stderr, "cohfrac_softbody_peer: %s\n", what);
  return 2;
}

static int run(int argc, char **argv)
{
  if (argc < 2 || argv[1][0] == '-')
    return bad("usage: cohfrac_softbody_peer MESH_BASE [--steps N] [--dt S] [--iterations K] "
               "[--speed V] [--warmup W]");
  double steps = 20, dt = 5e-6, iters = 3, speed = 3.1, warmup = 2;
  for (int i = 2; i < argc; i += 2) {
    double *dst = !std::strcmp(argv[i], "--steps")        ? &steps
                  : !std::strcmp(argv[i], "--dt")         ? &dt
                  : !std::strcmp(argv[i], "--iterations") ? &iters
                  : !std::strcmp(argv[i], "--speed")      ? &speed
                  : !std::strcmp(argv[i], "--warmup")     ? &warmup
                                                          : 0;
    std::string msg = std::string("bad option ") + argv[i];
    if (!dst || i + 1 >= argc || !parse_num(argv[i + 1], *dst)) return bad(msg.c_str());
    bool is_int = dst != &dt && dst != &speed;
    if (is_int && (*dst != std::floor(*dst) || *dst > 1e9)) return bad(msg.c_str());
    if ((dst == &steps || dst == &iters || dst == &dt) ? *dst <= 0 : *dst < 0) return bad(msg.c_str());
  }
  const double t_setup = now_s(CLOCK_MONOTONIC);

  // Parse ourselves (doubles, comments, 0- or 1-based): Bullet's reader takes
  // neither comments nor a base of 1, and reads coordinates as float.
  const std::string base = argv[1], node_path = base + ".node", ele_path = base + ".ele";
  std::string node_txt, ele_txt;
  if (!read_file(node_path, node_txt)) return bad(("cannot read " + node_path).c_str());
  if (!read_file(ele_path, ele_txt)) return bad(("cannot read " + ele_path).c_str());
  std::vector<const char *> nl = data_lines(node_txt), el = data_lines(ele_txt);
  int nn = 0, nt = 0, dim = 0, corners = 0, idx = 0, first = 0;
  if (nl.size() < 2 || std::sscanf(nl[0], "%d %d", &nn, &dim) != 2 || dim != 3 || nn < 4 ||
      (size_t)nn + 1 > nl.size() || std::sscanf(nl[1], "%d", &first) != 1 || (first != 0 && first != 1))
    return bad(("bad header or first index in " + node_path).c_str());
  std::vector<btVector3> x(nn);
  // +90 degrees about x: the mesh's y-up becomes z-up.
  const btTransform rot(btQuaternion(0.7071067811865476, 0, 0, 0.7071067811865476));
  btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
  for (int i = 0; i < nn; ++i) {
    double p[3];
    if (std::sscanf(nl[i + 1], "%d %lf %lf %lf", &idx, &p[0], &p[1], &p[2]) != 4 || idx != i + first)
      return bad(("bad node line in " + node_path).c_str());
    x[i] = rot * btVector3(p[0], p[1], p[2]);
    lo.setMin(x[i]);
    hi.setMax(x[i]);
  }
  // Bounding-box centre over x = y = 0, lowest point 1 mm above the ground.
  const btVector3 shift(-0.5 * (lo.x() + hi.x()), -0.5 * (lo.y() + hi.y()), 0.001 - lo.z());
  for (int i = 0; i < nn; ++i) x[i] += shift;
  if (el.empty() || std::sscanf(el[0], "%d %d", &nt, &corners) != 2 || corners != 4 || nt < 1 ||
      (size_t)nt + 1 > el.size())
    return bad(("bad header in " + ele_path).c_str());
  std::vector<int> tet(4 * (size_t)nt);
  std::vector<uint64_t> edges;
  edges.reserve(6 * (size_t)nt);
  double volume = 0;
  for (int t = 0; t < nt; ++t) {
    int *v = &tet[4 * (size_t)t];
    if (std::sscanf(el[t + 1], "%d %d %d %d %d", &idx, &v[0], &v[1], &v[2], &v[3]) != 5)
      return bad(("bad tet line in " + ele_path).c_str());
    for (int k = 0; k < 4; ++k)
      if ((v[k] -= first) < 0 || v[k] >= nn) return bad(("node index out of range in " + ele_path).c_str());
    volume += std::fabs((x[v[1]] - x[v[0]]).dot((x[v[2]] - x[v[0]]).cross(x[v[3]] - x[v[0]]))) / 6;
    static const int pair[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (int e = 0; e < 6; ++e) {
      uint64_t a = (uint64_t)v[pair[e][0]], b = (uint64_t)v[pair[e][1]];
      edges.push_back(a < b ? (a << 32 | b) : (b << 32 | a));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  // Plain TetGen text for Bullet (0-based, placed coordinates), so what it
  // derives from positions at creation already matches the placed mesh.  Each
  // line ends "\0\n": Bullet sscanf()s every line of the whole remaining
  // buffer (glibc measures it: quadratic, 8 s at 200k tets); the NUL stops
  // that, and its line skipper only looks for '\n'.  Checked after creation.
  std::string node_s, ele_s;
  char line[128];
  auto put = [&line](std::string &s, int len) { s.append(line, len).append("\0\n", 2); };
  put(node_s, std::snprintf(line, sizeof line, "%d 3 0 0", nn));
  for (int i = 0; i < nn; ++i)
    put(node_s, std::snprintf(line, sizeof line, "%d %.17g %.17g %.17g", i, x[i].x(), x[i].y(), x[i].z()));
  put(ele_s, std::snprintf(line, sizeof line, "%d 4 0", nt));
  for (int t = 0; t < nt; ++t) {
    const int *v = &tet[4 * (size_t)t];
    put(ele_s, std::snprintf(line, sizeof line, "%d %d %d %d %d", t, v[0], v[1], v[2], v[3]));
  }

  // The world lives on the stack: nothing of ours to allocate or check there.
  // The ground comes first so that it outlives the world on every return path.
  // The ground z = 0 as the top face of a static box, not a btStaticPlaneShape:
  // Bullet 3.24's sparse SDF gives distance 0 to any non-convex shape, so with
  // a plane every node reads as a contact (normal (1,0,0)) and is shoved.
  btBoxShape ground_shape(btVector3(20, 20, 1));
  btRigidBody ground(btRigidBody::btRigidBodyConstructionInfo(0, 0, &ground_shape));
  ground.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -1)));
  const btVector3 gravity(0, 0, -9.81);
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(gravity);
  btSoftBodyWorldInfo &info = world.getWorldInfo();
  info.m_gravity = gravity;
  world.addRigidBody(&ground);

  btSoftBody *psb = btSoftBodyHelpers::CreateFromTetGenData(info, ele_s.c_str(), 0, node_s.c_str(),
                                                            false, false, true);
  bool same = psb && psb->m_nodes.size() == nn && psb->m_tetras.size() == nt;
  for (int t = 0; same && t < nt; ++t)  // Bullet built exactly the tets we gave it
    for (int k = 0; k < 4; ++k) same = same && psb->m_tetras[t].m_n[k] == &psb->m_nodes[tet[4 * (size_t)t + k]];
  if (!same) {
    std::fprintf(stderr, "cohfrac_softbody_peer: cannot build the soft body world\n");
    delete psb;
    return 5;
  }
  // Bullet read the coordinates as float: put back the exact ones before the
  // links take their rest lengths from them.
  for (int i = 0; i < nn; ++i) psb->m_nodes[i].m_x = psb->m_nodes[i].m_q = x[i];
  // One link per unique edge, no existence check (Bullet's is linear per link).
  psb->m_links.reserve((int)edges.size());
  for (size_t e = 0; e < edges.size(); ++e)
    psb->appendLink((int)(edges[e] >> 32), (int)(edges[e] & 0xffffffffu), 0, false);
  psb->m_materials[0]->m_kLST = 0.9;
  psb->m_cfg.piterations = (int)iters;
  psb->m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
  psb->setTotalMass(2400 * volume, false);
  psb->setVelocity(btVector3(0, 0, -speed));
  // Bullet's default 0.25 m contact margin would put the bottom 25 cm of the
  // bunny in contact and lift it; 1 mm is the gap the scene starts with.
  psb->getCollisionShape()->setMargin(0.001);
  world.addSoftBody(psb);
  std::printf("mesh: %s tets=%d nodes=%d unique_edges=%d links=%d faces=%d volume=%.6g m^3 mass=%.6g kg\n",
              base.c_str(), nt, nn, (int)edges.size(), psb->m_links.size(), psb->m_faces.size(), volume,
              2400 * volume);
  std::printf("setup: %.3f s\n", now_s(CLOCK_MONOTONIC) - t_setup);

  for (int s = 0; s < (int)warmup; ++s) world.stepSimulation(dt, 0);  // untimed
  std::vector<double> ms((size_t)steps);
  const double cpu0 = now_s(CLOCK_PROCESS_CPUTIME_ID);
  for (size_t s = 0; s < ms.size(); ++s) {
    const double t0 = now_s(CLOCK_MONOTONIC);
    world.stepSimulation(dt, 0);  // 0 max sub-steps: exactly one internal step of dt
    ms[s] = 1e3 * (now_s(CLOCK_MONOTONIC) - t0);
  }
  const double cpu_ms = 1e3 * (now_s(CLOCK_PROCESS_CPUTIME_ID) - cpu0) / (double)ms.size();

  double zmin = BT_LARGE_FLOAT;
  bool finite = true;
  for (int i = 0; i < psb->m_nodes.size(); ++i) {
    const btVector3 &p = psb->m_nodes[i].m_x;
    finite = finite && std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
    zmin = std::min(zmin, (double)p.z());
  }
  std::printf("after: lowest node z=%.9g m finite=%s\n", zmin, finite ? "yes" : "no");
  world.removeSoftBody(psb);
  delete psb;
  world.removeRigidBody(&ground);
  if (!finite) {
    std::fprintf(stderr, "cohfrac_softbody_peer: node positions are not finite after the run\n");
    return 4;
  }

  std::sort(ms.begin(), ms.end());
  const size_t n = ms.size();
  const double median = (n % 2) ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  std::printf("peer: tets=%d nodes=%d links=%d steps=%d dt=%g ms_min=%.4f ms_median=%.4f cpu_ms=%.4f\n", nt,
              nn, (int)edges.size(), (int)n, dt, ms[0], median, cpu_ms);
  return 0;
}

int main(int argc, char **argv)
{
  try {
    return run(argc, argv);
  } catch (const std::bad_alloc &) {  // our vectors and strings; Bullet's own allocator does not throw
    std::fprintf(stderr, "cohfrac_softbody_peer: out of memory building the soft body world\n");
    return 5;
  }
}
