// Load time of a glb through tinygltf (images not decoded), best of 10.
#include <tiny_gltf.h>
#include <chrono>
#include <cstdio>
static bool noimg(tinygltf::Image *, const int, std::string *, std::string *, int, int,
                  const unsigned char *, int, void *)
{
    return true;
}
int main(int argc, char **argv)
{
    double best = 1e9;
    for (int i = 0; i < 10; i++) {
        auto t0 = std::chrono::steady_clock::now();
        tinygltf::TinyGLTF l;
        l.SetImageLoader(noimg, nullptr);
        tinygltf::Model m;
        std::string e, w;
        if (!l.LoadBinaryFromFile(&m, &e, &w, argv[1])) {
            printf("fail %s\n", e.c_str());
            return 1;
        }
        double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (t < best)
            best = t;
    }
    printf("%s: tinygltf best %.4f s\n", argv[1], best);
}
