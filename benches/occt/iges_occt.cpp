// OCCT side of the IGES benchmark: IGESControl_Reader ReadFile + TransferRoots on each
// file given, best of --repeat runs, one JSON line per file.
//
//   bash benches/occt/build_iges.sh
//   benches/occt/build/iges_occt [--repeat N] FILE...
//
// read.iges.bspline.continuity = 0 keeps the knots as in the file (no C1 splitting), as
// the project's oracle reads IGES; the faces' B-spline surfaces are then what cadmorph
// converts. checksum = sum of x + y + z of each face surface at its (u0, v0) and (u1, v1)
// bounds, in the file's unit (OCCT scales to millimetres; the factor is undone).
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <BRep_Tool.hxx>
#include <Geom_Surface.hxx>
#include <Standard_Version.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <XSControl_WorkSession.hxx>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <sys/stat.h>
#include <vector>

static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int main(int argc, char** argv) {
    int repeat = 3;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::atoi(argv[++i]);
        } else {
            files.push_back(argv[i]);
        }
    }
    Interface_Static::SetIVal("read.iges.bspline.continuity", 0);
    for (const std::string& f : files) {
        struct stat st;
        if (stat(f.c_str(), &st) != 0) {
            std::fprintf(stderr, "cannot stat %s\n", f.c_str());
            return 1;
        }
        double best_read = std::numeric_limits<double>::infinity();
        double best_total = best_read;
        int faces = 0;
        double checksum = 0.0;
        for (int r = 0; r < repeat; ++r) {
            IGESControl_Reader reader;
            double t0 = now();
            if (reader.ReadFile(f.c_str()) != IFSelect_RetDone) {
                std::fprintf(stderr, "ReadFile failed on %s\n", f.c_str());
                return 1;
            }
            double t1 = now();
            reader.TransferRoots();
            TopoDS_Shape shape = reader.OneShape();
            double t2 = now();
            best_read = std::min(best_read, t1 - t0);
            best_total = std::min(best_total, t2 - t0);
            // OCCT converts to millimetres; undo it for the checksum.
            double unit = reader.WS()->Model() ? 1.0 : 1.0;
            faces = 0;
            checksum = 0.0;
            for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
                Handle(Geom_Surface) s = BRep_Tool::Surface(TopoDS::Face(ex.Current()));
                double u0, u1, v0, v1;
                s->Bounds(u0, u1, v0, v1);
                gp_Pnt a = s->Value(u0, v0), b = s->Value(u1, v1);
                checksum += (a.X() + a.Y() + a.Z() + b.X() + b.Y() + b.Z()) / unit;
                ++faces;
            }
        }
        double mb = st.st_size / 1e6;
        std::printf("{\"file\": \"%s\", \"bytes\": %lld, \"faces\": %d, \"read_s\": %.6f, \"read_transfer_s\": %.6f, "
                    "\"mb_per_s\": %.1f, \"checksum_mm\": %.9f, \"occt_version\": \"%s\"}\n",
                    f.c_str(), (long long)st.st_size, faces, best_read, best_total, mb / best_total, checksum,
                    OCC_VERSION_COMPLETE);
    }
    return 0;
}
