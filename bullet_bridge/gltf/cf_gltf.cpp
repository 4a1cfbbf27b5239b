// glTF 2.0 output through tinygltf (see cf_gltf.h).  Every accessor lives in
// one buffer: per node its positions, indices, and (when animated) key
// times, translations, rotations and scales.
// Debian's libtinygltf is a shared library: its header only declares.
#include <tiny_gltf.h>

#include "cf_gltf.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

// Append raw bytes to the buffer (4-byte aligned) and a view on them.
int add_view(tinygltf::Model &m, const void *data, size_t bytes, int target)
{
    std::vector<unsigned char> &buf = m.buffers[0].data;
    while (buf.size() % 4)
        buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    if (target)
        v.target = target;
    const unsigned char *p = static_cast<const unsigned char *>(data);
    buf.insert(buf.end(), p, p + bytes);
    m.bufferViews.push_back(v);
    return static_cast<int>(m.bufferViews.size() - 1);
}

// An accessor of `count` elements of `type` (TINYGLTF_TYPE_*), with the
// float min/max glTF requires on positions and animation inputs.
int add_accessor(tinygltf::Model &m, const void *data, size_t count, int type, int ctype,
                 int ncomp, int target, bool bounds)
{
    const size_t esize = 4; // float or unsigned int
    tinygltf::Accessor a;
    a.bufferView = add_view(m, data, count * ncomp * esize, target);
    a.componentType = ctype;
    a.count = count;
    a.type = type;
    if (bounds && ctype == TINYGLTF_COMPONENT_TYPE_FLOAT && count > 0) {
        const float *f = static_cast<const float *>(data);
        a.minValues.assign(ncomp, f[0]);
        a.maxValues.assign(ncomp, f[0]);
        for (size_t i = 0; i < count; ++i)
            for (int k = 0; k < ncomp; ++k) {
                a.minValues[k] = std::min(a.minValues[k], (double)f[i * ncomp + k]);
                a.maxValues[k] = std::max(a.maxValues[k], (double)f[i * ncomp + k]);
            }
    }
    m.accessors.push_back(a);
    return static_cast<int>(m.accessors.size() - 1);
}

void add_channel(tinygltf::Model &m, tinygltf::Animation &anim, int node, int input, int output,
                 const char *path, const char *interpolation)
{
    tinygltf::AnimationSampler s;
    s.input = input;
    s.output = output;
    s.interpolation = interpolation;
    anim.samplers.push_back(s);
    tinygltf::AnimationChannel c;
    c.sampler = static_cast<int>(anim.samplers.size() - 1);
    c.target_node = node;
    c.target_path = path;
    anim.channels.push_back(c);
    (void)m;
}

} // namespace

extern "C" int cfg_write_glb(const char *path, const cfg_node *nodes, int n_nodes,
                             const char *animation, char *err, size_t errlen)
{
    try {
        tinygltf::Model m;
        m.asset.version = "2.0";
        m.asset.generator = "cohfrac";
        m.buffers.resize(1);
        tinygltf::Scene scene;
        tinygltf::Animation anim;
        anim.name = animation ? animation : "animation";
        // The crack faces' material, shared: the inside of the solid.
        int crack_material = -1;
        for (int i = 0; i < n_nodes; ++i) {
            const cfg_node &n = nodes[i];
            tinygltf::Material mat;
            mat.name = n.name ? n.name : "";
            mat.pbrMetallicRoughness.baseColorFactor = {n.color[0], n.color[1], n.color[2],
                                                        n.color[3]};
            mat.pbrMetallicRoughness.metallicFactor = 0.0;
            mat.pbrMetallicRoughness.roughnessFactor = 0.8;
            m.materials.push_back(mat);
            int outer_material = static_cast<int>(m.materials.size() - 1);
            if (n.n_inner > 0 && crack_material < 0) {
                tinygltf::Material crack;
                crack.name = "crack";
                crack.pbrMetallicRoughness.baseColorFactor = {0.85, 0.83, 0.78, 1.0};
                crack.pbrMetallicRoughness.metallicFactor = 0.0;
                crack.pbrMetallicRoughness.roughnessFactor = 1.0;
                m.materials.push_back(crack);
                crack_material = static_cast<int>(m.materials.size() - 1);
            }
            int position =
                add_accessor(m, n.positions, n.n_vertices, TINYGLTF_TYPE_VEC3,
                             TINYGLTF_COMPONENT_TYPE_FLOAT, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
            tinygltf::Mesh mesh;
            mesh.name = mat.name;
            const int parts[2][2] = {{0, n.n_triangles - n.n_inner},
                                     {n.n_triangles - n.n_inner, n.n_triangles}};
            for (int k = 0; k < 2; ++k) {
                int count = parts[k][1] - parts[k][0];
                if (count <= 0)
                    continue;
                tinygltf::Primitive prim;
                prim.attributes["POSITION"] = position;
                prim.indices = add_accessor(m, n.indices + 3 * (size_t)parts[k][0],
                                            3 * (size_t)count, TINYGLTF_TYPE_SCALAR,
                                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 1,
                                            TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
                prim.material = k == 0 ? outer_material : crack_material;
                prim.mode = TINYGLTF_MODE_TRIANGLES;
                mesh.primitives.push_back(prim);
            }
            m.meshes.push_back(mesh);
            tinygltf::Node node;
            node.name = mat.name;
            node.mesh = static_cast<int>(m.meshes.size() - 1);
            if (n.n_extras > 0) {
                tinygltf::Value::Object extras;
                for (int k = 0; k < n.n_extras; ++k)
                    extras[n.extra_keys[k]] = tinygltf::Value(n.extra_values[k]);
                node.extras = tinygltf::Value(extras);
            }
            if (n.n_keys > 0) { // the rest pose is the first key
                node.translation = {n.translation[0], n.translation[1], n.translation[2]};
                node.rotation = {n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
                node.scale = {n.scale[0], n.scale[0], n.scale[0]};
            }
            m.nodes.push_back(node);
            int id = static_cast<int>(m.nodes.size() - 1);
            scene.nodes.push_back(id);
            if (n.n_keys == 0)
                continue;
            int input = add_accessor(m, n.times, n.n_keys, TINYGLTF_TYPE_SCALAR,
                                     TINYGLTF_COMPONENT_TYPE_FLOAT, 1, 0, true);
            int tr = add_accessor(m, n.translation, n.n_keys, TINYGLTF_TYPE_VEC3,
                                  TINYGLTF_COMPONENT_TYPE_FLOAT, 3, 0, false);
            int ro = add_accessor(m, n.rotation, n.n_keys, TINYGLTF_TYPE_VEC4,
                                  TINYGLTF_COMPONENT_TYPE_FLOAT, 4, 0, false);
            std::vector<float> s3(3 * (size_t)n.n_keys);
            for (int k = 0; k < n.n_keys; ++k)
                s3[3 * k] = s3[3 * k + 1] = s3[3 * k + 2] = n.scale[k];
            int sc = add_accessor(m, s3.data(), n.n_keys, TINYGLTF_TYPE_VEC3,
                                  TINYGLTF_COMPONENT_TYPE_FLOAT, 3, 0, false);
            add_channel(m, anim, id, input, tr, "translation", "LINEAR");
            add_channel(m, anim, id, input, ro, "rotation", "LINEAR");
            add_channel(m, anim, id, input, sc, "scale", "STEP");
        }
        m.scenes.push_back(scene);
        m.defaultScene = 0;
        if (!anim.channels.empty())
            m.animations.push_back(anim);
        tinygltf::TinyGLTF writer;
        if (!writer.WriteGltfSceneToFile(&m, path, true, true, true, true)) {
            std::snprintf(err, errlen, "tinygltf could not write %s", path);
            return -1;
        }
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "writing %s: %s", path, e.what());
    } catch (...) {
        std::snprintf(err, errlen, "writing %s: unknown error", path);
    }
    return -1;
}
