// OCCT side of the STEP read benchmark (benches/step_vs_occt.sh): for each file, the best
// of N runs of STEPControl_Reader::ReadFile + TransferRoots, printed as one JSON line
// {"file", "bytes", "read_s", "transfer_s", "total_s", "mb_per_s", "faces"}.
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Shape.hxx>
#include <IFSelect_ReturnStatus.hxx>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int main(int argc, char** argv) {
    int repeat = 3;
    int first = 1;
    if (argc > 2 && std::strcmp(argv[1], "--repeat") == 0) {
        repeat = std::atoi(argv[2]);
        first = 3;
    }
    for (int i = first; i < argc; ++i) {
        std::ifstream f(argv[i], std::ios::binary | std::ios::ate);
        const double bytes = static_cast<double>(f.tellg());
        double best_read = 1e30, best_transfer = 1e30, best_total = 1e30;
        int faces = 0;
        for (int r = 0; r < repeat; ++r) {
            STEPControl_Reader reader;
            const double t0 = now();
            if (reader.ReadFile(argv[i]) != IFSelect_RetDone) {
                std::fprintf(stderr, "%s: read failed\n", argv[i]);
                return 1;
            }
            const double t1 = now();
            reader.TransferRoots();
            const TopoDS_Shape shape = reader.OneShape();
            const double t2 = now();
            faces = 0;
            for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) ++faces;
            if (t2 - t0 < best_total) {
                best_total = t2 - t0;
                best_read = t1 - t0;
                best_transfer = t2 - t1;
            }
        }
        std::printf("{\"file\": \"%s\", \"bytes\": %.0f, \"read_s\": %.6f, \"transfer_s\": %.6f, \"total_s\": %.6f, "
                    "\"mb_per_s\": %.3f, \"faces\": %d}\n",
                    argv[i], bytes, best_read, best_transfer, best_total, bytes / 1e6 / best_total, faces);
    }
    return 0;
}
