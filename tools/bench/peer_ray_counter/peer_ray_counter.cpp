// LD_PRELOAD shim for bench_render: counts the rays Embree's tutorial path tracer (the peer)
// traces, so that its rays per sample and rays/s can be compared with ours. It interposes the
// two single-ray queries the peer calls, forwards them to the real libembree3, and writes
// "<closest-hit rays> <occlusion rays>" to $CHORUS_RAY_COUNT_FILE when the process exits.
#include <dlfcn.h>
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace {

std::atomic<unsigned long long> closestHitRays{0}, occlusionRays{0};

template <typename Function>
Function realFunction(const char* name) {
  void* symbol = dlsym(RTLD_NEXT, name);
  if (!symbol) {
    std::fprintf(stderr, "peer_ray_counter: %s not found in the loaded libraries\n", name);
    std::abort();
  }
  return reinterpret_cast<Function>(symbol);
}

struct ReportAtExit {
  ~ReportAtExit() {
    const char* path = std::getenv("CHORUS_RAY_COUNT_FILE");
    if (!path) return;
    if (FILE* file = std::fopen(path, "w")) {
      std::fprintf(file, "%llu %llu\n", closestHitRays.load(), occlusionRays.load());
      std::fclose(file);
    }
  }
} reportAtExit;

}  // namespace

extern "C" {

void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit) {
  using Query = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*);
  static const Query real = realFunction<Query>("rtcIntersect1");
  closestHitRays.fetch_add(1, std::memory_order_relaxed);
  real(scene, context, rayhit);
}

void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray) {
  using Query = void (*)(RTCScene, RTCIntersectContext*, RTCRay*);
  static const Query real = realFunction<Query>("rtcOccluded1");
  occlusionRays.fetch_add(1, std::memory_order_relaxed);
  real(scene, context, ray);
}

}  // extern "C"
