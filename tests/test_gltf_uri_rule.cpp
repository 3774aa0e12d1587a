/*
 * test_gltf_uri_rule.cpp - formats/vdsh_gltf_uri.h against tinygltf's own
 * dlib::urldecode, which the baker cannot change (tinygltf applies it to
 * every buffer URI before reading the file): the same bytes, NUL bytes
 * included, for hand-picked URIs ('+', "%20", "%2B", "%2z", "%zz", "%00",
 * '%' among the last two characters) and 200000 random ones over an
 * alphabet of those characters. vdsh-export --source decodes with the
 * header too, so a URI names one file in bake and export
 * (tests/test_gltf_uri.py runs both programs).
 */
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <cstdio>
#include <string>
#include <vector>

#include "vdsh_gltf_uri.h"

static std::string ours(const std::string &u)
{
    std::vector<char> out(u.size() + 1);
    size_t n = vdsh_gltf_uri_decode(u.data(), u.size(), out.data());
    return std::string(out.data(), n);
}

int main()
{
    int failures = 0;
    auto check = [&](const std::string &u) {
        std::string want = tinygltf::dlib::urldecode(u), got = ours(u);
        if (got != want && failures++ < 10)
            std::fprintf(stderr, "uri '%s' (%zu bytes): tinygltf %zu bytes, ours %zu bytes\n",
                         u.c_str(), u.size(), want.size(), got.size());
    };
    const char *cases[] = {"a+b.bin", "a%20b+c.bin", "Cesium%20Logo%2B1.png",
                           "%2z",     "%zz",         "a%00.bin",
                           "a%4",     "a%",          "%",
                           "%%41",    "+%+",         "%41%42%43",
                           ""};
    for (const char *c : cases)
        check(c);
    check(std::string("a\0%2541", 7));
    static const char alphabet[] = "%+aZ09fFgG/. \x00\xff";
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 200000; i++) {
        s ^= s >> 12, s ^= s << 25, s ^= s >> 27;
        uint64_t r = s * 0x2545F4914F6CDD1Dull;
        std::string u;
        for (int k = 0, n = (int)(r % 9); k < n; k++) {
            s ^= s >> 12, s ^= s << 25, s ^= s >> 27;
            u += alphabet[(s * 0x2545F4914F6CDD1Dull >> 33) % (sizeof alphabet - 1)];
        }
        check(u);
    }
    if (ours("a%20b+c.bin") != "a b c.bin")
        failures++, std::fprintf(stderr, "a%%20b+c.bin is not 'a b c.bin'\n");
    std::printf("gltf uri rule: %d of 200014 URIs differ from tinygltf's\n", failures);
    return failures ? 1 : 0;
}
