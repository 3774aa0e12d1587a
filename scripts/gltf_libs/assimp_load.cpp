// Load time of a glb through assimp (aiProcess_Triangulate only), best of 10.
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <assimp/postprocess.h>
#include <chrono>
#include <cstdio>
int main(int argc, char **argv)
{
    double best = 1e9;
    unsigned nt = 0;
    for (int i = 0; i < 10; i++) {
        auto t0 = std::chrono::steady_clock::now();
        Assimp::Importer imp;
        const aiScene *s = imp.ReadFile(argv[1], aiProcess_Triangulate);
        if (!s) {
            printf("fail %s\n", imp.GetErrorString());
            return 1;
        }
        nt = 0;
        for (unsigned m = 0; m < s->mNumMeshes; m++)
            nt += s->mMeshes[m]->mNumFaces;
        double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (t < best)
            best = t;
    }
    printf("%s: %u triangles, best %.4f s\n", argv[1], nt, best);
}
