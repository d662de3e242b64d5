// Prints the T-spline that GrapeTec/T-SPLINE reads from a .tsm file: for every face its
// parameter rectangle, and for every blending function on it the control point, its weight
// and its u and v knot vectors (GrapeTec's global parameters). Built and run by
// scripts/grapetec/reference; evaluated exactly by scripts/grapetec/evaluate.py.
#include <extractor.h>
#include <factory.h>
#include <finder.h>
#include <rhbuilder.h>
#include <tspline.h>
#include <iomanip>
#ifdef use_namespace
using namespace TSPLINE;
#endif

int main(int argc, char **argv) {
  if (argc < 2) {
    std::cerr << "usage: dump FILE.tsm\n";
    return 2;
  }
  RhBuilderPtr reader = makePtr<RhBuilder>(std::string(argv[1]));
  TSplinePtr spline = reader->findTSpline();
  TFinderPtr finder = makePtr<TFinder>(spline->getCollector());
  std::vector<std::string> faces;
  reader->findTFaceNames(faces);
  std::cout << std::setprecision(17);
  for (const std::string &name : faces) {
    TFacePtr f = finder->findByName<TFace>(name);
    Parameter nw = f->northWest(), se = f->southEast();
    std::cout << "face " << name << " " << nw.s() << " " << se.s() << " " << se.t() << " "
              << nw.t() << "\n";
    for (TNodVIterator it = f->blendingNodeIteratorBegin(); it != f->blendingNodeIteratorEnd();
         it++) {
      std::vector<Real> u, v;
      Point3D p;
      Real w;
      TNodeV4Ptr n = castPtr<TNodeV4>(*it);
      TExtractor::extractUVKnotsFromTNodeV4(n, u, v);
      TExtractor::extractRationalPointFromTNodeV4(n, p, w);
      std::cout << "blend " << p.x() << " " << p.y() << " " << p.z() << " " << w << " u";
      for (Real x : u) std::cout << " " << x;
      std::cout << " v";
      for (Real x : v) std::cout << " " << x;
      std::cout << "\n";
    }
  }
  return 0;
}
