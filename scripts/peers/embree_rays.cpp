// Peer: Embree 3 closest-hit queries over the rays that pinhole's bvh_speed
// example dumps (PINHOLE_DUMP_RAYS): the same triangles, the same incoherent
// bounce rays, one thread, rtcIntersect1, best of 7. scripts/bench_rays.sh
// builds and runs it beside pinhole's own figure.
//
//   embree_rays SCENE.tris SCENE.rays
#include <embree3/rtcore.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>
static std::vector<float> slurp(const char* p) {
  std::ifstream in(p, std::ios::binary); std::vector<char> b((std::istreambuf_iterator<char>(in)), {});
  std::vector<float> f(b.size() / 4); std::memcpy(f.data(), b.data(), f.size() * 4); return f;
}
static double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: %s SCENE.tris SCENE.rays\n", argv[0]); return 2; }
  auto tris = slurp(argv[1]); auto rays = slurp(argv[2]);
  size_t nt = tris.size() / 9, nr = rays.size() / 6;
  RTCDevice dev = rtcNewDevice("threads=1");
  RTCScene scene = rtcNewScene(dev);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  float* vb = (float*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nt * 3);
  std::copy(tris.begin(), tris.end(), vb);
  unsigned* ib = (unsigned*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nt);
  for (size_t i = 0; i < nt * 3; ++i) ib[i] = i;
  rtcCommitGeometry(g); rtcAttachGeometry(scene, g); rtcReleaseGeometry(g); rtcCommitScene(scene);
  double best = 1e9; long hits = 0;
  for (int rep = 0; rep < 7; ++rep) {
    RTCIntersectContext ctx; rtcInitIntersectContext(&ctx);
    double s = now(); hits = 0;
    for (size_t i = 0; i < nr; ++i) {
      RTCRayHit rh{}; const float* r = &rays[6 * i];
      rh.ray.org_x = r[0]; rh.ray.org_y = r[1]; rh.ray.org_z = r[2];
      rh.ray.dir_x = r[3]; rh.ray.dir_y = r[4]; rh.ray.dir_z = r[5];
      rh.ray.tnear = 0; rh.ray.tfar = INFINITY; rh.ray.mask = -1; rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &ctx, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    best = std::min(best, now() - s);
  }
  std::printf("embree3 rays=%zu hits=%ld ns_per_ray_1_thread=%.1f\n", nr, hits, best * 1e9 / nr);
  // The same rays in packets of 16, consecutive rays together (neighbouring
  // pixels' bounces), marked incoherent: how a wavefront renderer built on
  // Embree (Mitsuba 3's LLVM variants) hands it its rays.
  best = 1e9;
  for (int rep = 0; rep < 7; ++rep) {
    RTCIntersectContext ctx; rtcInitIntersectContext(&ctx); ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    double s = now(); hits = 0;
    for (size_t i0 = 0; i0 < nr; i0 += 16) {
      alignas(64) RTCRayHit16 rh; alignas(64) int valid[16];
      for (int k = 0; k < 16; ++k) {
        size_t i = std::min(i0 + k, nr - 1); const float* r = &rays[6 * i];
        valid[k] = i0 + k < nr ? -1 : 0;
        rh.ray.org_x[k] = r[0]; rh.ray.org_y[k] = r[1]; rh.ray.org_z[k] = r[2];
        rh.ray.dir_x[k] = r[3]; rh.ray.dir_y[k] = r[4]; rh.ray.dir_z[k] = r[5];
        rh.ray.tnear[k] = 0; rh.ray.tfar[k] = INFINITY; rh.ray.mask[k] = -1; rh.ray.time[k] = 0; rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, scene, &ctx, &rh);
      for (int k = 0; k < 16; ++k) hits += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
    }
    best = std::min(best, now() - s);
  }
  std::printf("embree3 packets16 rays=%zu hits=%ld ns_per_ray_1_thread=%.1f\n", nr, hits, best * 1e9 / nr);
}
