#include "api/surface_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "api/handles.hpp"
#include "core/error.hpp"

namespace gmpu::api {

namespace {

// A cluster's failure as the owner's: its status, its message less the status name that
// recording will put back.
void check(gmpu_status status, size_t part, size_t parts) {
    if (status == GMPU_OK) return;
    std::string message = gmpu_last_error();
    const std::string name = std::string(gmpu_status_name(status)) + ": ";
    if (message.compare(0, name.size(), name) == 0) message.erase(0, name.size());
    throw Error(status, "cluster " + std::to_string(part + 1) + " of " + std::to_string(parts) +
                            " (the points form separate clusters, each reconstructed at its own scale): " + message);
}

double box_distance(const std::array<double, 6> &box, const double *p) {
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        const double e = std::max({box[d] - p[d], 0.0, p[d] - box[3 + d]});
        s += e * e;
    }
    return s;
}

}  // namespace

// A cluster's progress as a share of the owner's stage.
struct SurfaceParts::Progress {
    gmpu_progress_fn fn;
    void *user;
    double offset, share;
    static int report(void *self, gmpu_stage stage, double fraction) {
        const auto *p = static_cast<const Progress *>(self);
        return p->fn ? p->fn(p->user, stage, p->offset + p->share * fraction) : 0;
    }
};

SurfaceParts::SurfaceParts(const Clusters &clusters) : members_(clusters.count), boxes_(clusters.boxes) {
    for (size_t i = 0; i < clusters.labels.size(); ++i) members_[clusters.labels[i]].push_back(uint32_t(i));
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const auto &b : boxes_)
        for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], b[d]), hi[d] = std::max(hi[d], b[3 + d]);
    diagonal_ = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    parts_.reserve(clusters.count);
    for (size_t k = 0; k < clusters.count; ++k) {
        gmpu_surface *part = nullptr;
        check(gmpu_surface_create(&part), k, clusters.count);
        parts_.push_back(part);
    }
}

SurfaceParts::~SurfaceParts() {
    for (gmpu_surface *part : parts_) gmpu_surface_destroy(part);
}

void SurfaceParts::set_param(gmpu_param key, double value) {
    for (size_t k = 0; k < parts_.size(); ++k) check(gmpu_surface_set_param(parts_[k], key, value), k, size());
}

// The rows of `members` (input indices), copied packed from an array of 3 × T each, stride
// bytes apart (0: packed).
template <class T>
void gather(const T *xyz, size_t stride, const std::vector<uint32_t> &members, std::vector<T> &out) {
    if (stride == 0) stride = 3 * sizeof(T);
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    out.resize(3 * members.size());
    for (size_t j = 0; j < members.size(); ++j) std::memcpy(&out[3 * j], bytes + members[j] * stride, 3 * sizeof(T));
}

template <class T>
void SurfaceParts::set_points(const T *xyz, size_t, size_t stride) {
    std::vector<T> own;
    for (size_t k = 0; k < parts_.size(); ++k) {
        gather(xyz, stride, members_[k], own);
        if constexpr (std::is_same_v<T, double>)
            check(gmpu_surface_set_points_f64(parts_[k], own.data(), members_[k].size(), 0), k, size());
        else
            check(gmpu_surface_set_points_f32(parts_[k], own.data(), members_[k].size(), 0), k, size());
    }
}

template <class T>
void SurfaceParts::set_normals(const T *nxyz, size_t, size_t stride) {
    std::vector<T> own;
    for (size_t k = 0; k < parts_.size(); ++k) {
        gather(nxyz, stride, members_[k], own);
        if constexpr (std::is_same_v<T, double>)
            check(gmpu_surface_set_normals_f64(parts_[k], own.data(), members_[k].size(), 0), k, size());
        else
            check(gmpu_surface_set_normals_f32(parts_[k], own.data(), members_[k].size(), 0), k, size());
    }
}

template <class Verb>
void SurfaceParts::each(gmpu_progress_fn fn, void *user, Verb &&verb) {
    double total = 0.0, done = 0.0;
    for (const auto &m : members_) total += double(m.size());
    for (size_t k = 0; k < parts_.size(); ++k) {
        const double points = double(members_[k].size());
        Progress progress{fn, user, done / total, points / total};
        check(gmpu_surface_set_progress(parts_[k], Progress::report, &progress), k, size());
        const gmpu_status status = verb(parts_[k]);
        gmpu_surface_set_progress(parts_[k], nullptr, nullptr);
        check(status, k, size());
        done += points;
    }
}

void SurfaceParts::fit(gmpu_progress_fn fn, void *user) { each(fn, user, gmpu_surface_fit); }
void SurfaceParts::orient(gmpu_progress_fn fn, void *user) { each(fn, user, gmpu_surface_orient); }

Mesh SurfaceParts::polygonize(gmpu_progress_fn fn, void *user) {
    Mesh all;
    each(fn, user, [&](gmpu_surface *part) {
        gmpu_mesh *m = nullptr;
        const gmpu_status status = gmpu_surface_polygonize(part, &m);
        if (status != GMPU_OK) return status;
        const Mesh &own = m->mesh;
        const size_t base = all.vertex_count();
        if (base + own.vertex_count() > std::numeric_limits<uint32_t>::max()) {
            gmpu_mesh_destroy(m);
            throw Error(GMPU_ERROR_LIMIT_EXCEEDED, "the clusters' meshes together have over 2^32 vertices");
        }
        all.vertices.insert(all.vertices.end(), own.vertices.begin(), own.vertices.end());
        all.normals.insert(all.normals.end(), own.normals.begin(), own.normals.end());
        for (uint32_t v : own.triangles) all.triangles.push_back(uint32_t(base + v));
        gmpu_mesh_destroy(m);
        return GMPU_OK;
    });
    return all;
}

void SurfaceParts::evaluate(const double *xyz, size_t count, double *values, double *gradients) const {
    std::vector<std::vector<size_t>> asked(parts_.size());
    for (size_t i = 0; i < count; ++i) {
        size_t best = 0;
        for (size_t k = 1; k < boxes_.size(); ++k)
            if (box_distance(boxes_[k], xyz + 3 * i) < box_distance(boxes_[best], xyz + 3 * i)) best = k;
        asked[best].push_back(i);
    }
    std::vector<double> q, v, g;
    for (size_t k = 0; k < parts_.size(); ++k) {
        const size_t n = asked[k].size();
        if (n == 0) continue;
        q.resize(3 * n), v.resize(n), g.resize(3 * n);
        for (size_t j = 0; j < n; ++j) std::memcpy(&q[3 * j], xyz + 3 * asked[k][j], 3 * sizeof(double));
        check(gmpu_surface_evaluate(parts_[k], q.data(), n, values ? v.data() : nullptr, gradients ? g.data() : nullptr),
              k, size());
        for (size_t j = 0; j < n; ++j) {
            if (values) values[asked[k][j]] = v[j];
            if (gradients) std::memcpy(gradients + 3 * asked[k][j], &g[3 * j], 3 * sizeof(double));
        }
    }
}

void SurfaceParts::copy_normals(double *out, size_t) const {
    std::vector<double> own;
    for (size_t k = 0; k < parts_.size(); ++k) {
        own.resize(3 * members_[k].size());
        check(gmpu_surface_copy_normals(parts_[k], own.data(), members_[k].size()), k, size());
        for (size_t j = 0; j < members_[k].size(); ++j) std::memcpy(out + 3 * size_t(members_[k][j]), &own[3 * j], 3 * sizeof(double));
    }
}

void SurfaceParts::copy_normals_at(const int64_t *indices, size_t count, double *out) const {
    // Per cluster: which of the asked points are its members, and their positions in it.
    std::vector<std::vector<int64_t>> local(parts_.size());
    std::vector<std::vector<size_t>> asked(parts_.size());
    for (size_t j = 0; j < count; ++j) {
        const auto i = uint32_t(indices[j]);
        for (size_t k = 0; k < parts_.size(); ++k) {
            const auto at = std::lower_bound(members_[k].begin(), members_[k].end(), i);
            if (at == members_[k].end() || *at != i) continue;
            local[k].push_back(int64_t(at - members_[k].begin()));
            asked[k].push_back(j);
            break;
        }
    }
    std::vector<double> own;
    for (size_t k = 0; k < parts_.size(); ++k) {
        if (local[k].empty()) continue;
        own.resize(3 * local[k].size());
        check(gmpu_surface_copy_normals_at(parts_[k], local[k].data(), local[k].size(), own.data()), k, size());
        for (size_t m = 0; m < asked[k].size(); ++m) std::memcpy(out + 3 * asked[k][m], &own[3 * m], 3 * sizeof(double));
    }
}

double SurfaceParts::stat(gmpu_stat key) const {
    if (key == GMPU_STAT_BBOX_DIAGONAL) return diagonal_;
    size_t largest = 0;
    for (size_t k = 1; k < parts_.size(); ++k)
        if (members_[k].size() > members_[largest].size()) largest = k;
    double sum = 0.0, most = 0.0, v = 0.0;
    for (size_t k = 0; k < parts_.size(); ++k) {
        check(gmpu_surface_get_stat(parts_[k], key, &v), k, size());
        sum += v;
        most = std::max(most, v);
    }
    switch (key) {
        case GMPU_STAT_DEPTH:
        case GMPU_STAT_RESOLUTION: return most;
        case GMPU_STAT_NOISE:
        case GMPU_STAT_EFFECTIVE_ERROR:
            check(gmpu_surface_get_stat(parts_[largest], key, &v), largest, size());
            return v;
        default: return sum;
    }
}

template void SurfaceParts::set_points<double>(const double *, size_t, size_t);
template void SurfaceParts::set_points<float>(const float *, size_t, size_t);
template void SurfaceParts::set_normals<double>(const double *, size_t, size_t);
template void SurfaceParts::set_normals<float>(const float *, size_t, size_t);

}  // namespace gmpu::api
