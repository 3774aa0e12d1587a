/*
 * vdsh.c - the .vdsh reader and writer (see vdsh.h for the API and
 * VDSH.md for the byte layout and the reading rules).
 *
 * Reading is two passes over one buffer that holds the whole file: the
 * first walks the chunk headers and checks every CRC, the second checks
 * every rule of VDSH.md "Reading rules" on the bytes. Only then is the
 * vdsh_file allocated; its arrays point into the buffer, which is 16-byte
 * aligned, so every data array (all of which start at a multiple of 16 in
 * the file) is aligned too.
 *
 * Writing checks the caller's vdsh_file with the same value checks the
 * reader uses (check_* below), so the writer cannot produce a file that
 * the reader rejects, then emits the chunks from the caller's arrays
 * without copying them.
 */
#include "vdsh.h"
#include "vdsh_output.h"

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/*
 * Headers are encoded field by field, but the data arrays (POSN, NORM,
 * TRIS, COEF) are pointed at in the read buffer and written straight from
 * the caller's arrays: that is only correct on a little-endian host with
 * IEEE-754 floats.
 */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "vdsh.c supports little-endian hosts only (the file is little-endian)"
#endif
#elif !defined(_WIN32)
#error "vdsh.c: cannot tell this target's byte order; it must be little-endian"
#endif
_Static_assert(sizeof(float) == 4 && FLT_MANT_DIG == 24 && FLT_MAX_EXP == 128,
               "float must be IEEE-754 binary32");
_Static_assert(sizeof(double) == 8 && DBL_MANT_DIG == 53,
               "double must be IEEE-754 binary64");

enum {
    FILE_HEADER_SIZE = 32,
    CHUNK_HEADER_SIZE = 16,
    HEAD_SIZE = 128,
    STREAM_HEADER_SIZE = 48,
    STAT_SIZE = 32,
    TIME_SIZE = 64,
    SOURCE_FIXED_SIZE = 44, /* sha256, size, name_length */
    MAX_CHUNKS = 64
};

static const uint8_t vdsh_magic[8] = {0x56, 0x44, 0x53, 0x48,
                                      0x0D, 0x0A, 0x1A, 0x0A};

/* ------------------------------------------------------------------ */
/* Little-endian field access                                          */
/* ------------------------------------------------------------------ */

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
           (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

static float get_f32(const uint8_t *p)
{
    uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static double get_f64(const uint8_t *p)
{
    uint64_t u = get_u64(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put_u64(uint8_t *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(p, u);
}

static void put_f64(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    put_u64(p, u);
}

static uint32_t f32_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float f32_from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static uint64_t pad16(uint64_t n) { return (16 - (n & 15)) & 15; }

static int all_zero(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i])
            return 0;
    return 1;
}

/* ------------------------------------------------------------------ */
/* Messages                                                            */
/* ------------------------------------------------------------------ */

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static vdsh_result fail(vdsh_error *err, vdsh_result r, const char *name,
                        const char *fmt, ...)
{
    if (err) {
        int n = snprintf(err->msg, sizeof err->msg, "%s: ",
                         name ? name : "memory");
        if (n < 0 || (size_t)n >= sizeof err->msg)
            n = 0;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg + n, sizeof err->msg - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return r;
}

/* A short description of a failed check, filled by the check_* functions
 * and turned into a vdsh_error by the reader (VDSH_ERR_INVALID) or the
 * writer (VDSH_ERR_ARGUMENT). */
typedef struct why {
    char msg[400];
} why;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static int bad(why *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->msg, sizeof w->msg, fmt, ap);
    va_end(ap);
    return 0;
}

const char *vdsh_result_str(vdsh_result r)
{
    switch (r) {
    case VDSH_OK: return "success";
    case VDSH_ERR_IO: return "I/O error";
    case VDSH_ERR_OUT_OF_MEMORY: return "out of memory";
    case VDSH_ERR_NOT_VDSH: return "not a .vdsh file";
    case VDSH_ERR_VERSION: return "unsupported version";
    case VDSH_ERR_TRUNCATED: return "truncated";
    case VDSH_ERR_CRC: return "CRC mismatch";
    case VDSH_ERR_CHUNK: return "bad chunk structure";
    case VDSH_ERR_INVALID: return "invalid value";
    case VDSH_ERR_ARGUMENT: return "invalid argument";
    }
    return "unknown result";
}

static const char *name_of(uint32_t v, const char *const *names, uint32_t n)
{
    return v < n ? names[v] : "?";
}

const char *vdsh_method_name(uint32_t method)
{
    static const char *const n[] = {"paper", "full", "mirror", "lsq", "shadow"};
    return name_of(method, n, 5);
}

const char *vdsh_encoding_name(uint32_t encoding)
{
    static const char *const n[] = {"f32", "f16"};
    return name_of(encoding, n, 2);
}

const char *vdsh_quantity_name(uint32_t quantity)
{
    static const char *const n[] = {"distance", "distance2", "log-distance"};
    return name_of(quantity, n, 3);
}

const char *vdsh_window_name(uint32_t window)
{
    static const char *const n[] = {"none", "hann", "lanczos"};
    return name_of(window, n, 3);
}

const char *vdsh_sampling_name(uint32_t sampling)
{
    static const char *const n[] = {"sphere", "hemisphere"};
    return name_of(sampling, n, 2);
}

const char *vdsh_offset_rule_name(uint32_t rule)
{
    static const char *const n[] = {"none", "wb-avg"};
    return name_of(rule, n, 2);
}

/* ------------------------------------------------------------------ */
/* CRC-32 (ISO-HDLC, reflected 0xEDB88320), slice-by-8                 */
/* ------------------------------------------------------------------ */

/*
 * crc_table[0] is the classic byte table; crc_table[k][i] is the CRC of
 * byte i followed by k zero bytes, so eight bytes are folded per step with
 * eight independent lookups. Generated once by the bitwise definition
 * (tests/test_format.c checks the result against it on every length and
 * alignment); a constant table keeps the library free of lazy-init state.
 */
static const uint32_t crc_table[8][256] = {
    {
        0x00000000u, 0x77073096u, 0xee0e612cu, 0x990951bau, 0x076dc419u, 0x706af48fu,
        0xe963a535u, 0x9e6495a3u, 0x0edb8832u, 0x79dcb8a4u, 0xe0d5e91eu, 0x97d2d988u,
        0x09b64c2bu, 0x7eb17cbdu, 0xe7b82d07u, 0x90bf1d91u, 0x1db71064u, 0x6ab020f2u,
        0xf3b97148u, 0x84be41deu, 0x1adad47du, 0x6ddde4ebu, 0xf4d4b551u, 0x83d385c7u,
        0x136c9856u, 0x646ba8c0u, 0xfd62f97au, 0x8a65c9ecu, 0x14015c4fu, 0x63066cd9u,
        0xfa0f3d63u, 0x8d080df5u, 0x3b6e20c8u, 0x4c69105eu, 0xd56041e4u, 0xa2677172u,
        0x3c03e4d1u, 0x4b04d447u, 0xd20d85fdu, 0xa50ab56bu, 0x35b5a8fau, 0x42b2986cu,
        0xdbbbc9d6u, 0xacbcf940u, 0x32d86ce3u, 0x45df5c75u, 0xdcd60dcfu, 0xabd13d59u,
        0x26d930acu, 0x51de003au, 0xc8d75180u, 0xbfd06116u, 0x21b4f4b5u, 0x56b3c423u,
        0xcfba9599u, 0xb8bda50fu, 0x2802b89eu, 0x5f058808u, 0xc60cd9b2u, 0xb10be924u,
        0x2f6f7c87u, 0x58684c11u, 0xc1611dabu, 0xb6662d3du, 0x76dc4190u, 0x01db7106u,
        0x98d220bcu, 0xefd5102au, 0x71b18589u, 0x06b6b51fu, 0x9fbfe4a5u, 0xe8b8d433u,
        0x7807c9a2u, 0x0f00f934u, 0x9609a88eu, 0xe10e9818u, 0x7f6a0dbbu, 0x086d3d2du,
        0x91646c97u, 0xe6635c01u, 0x6b6b51f4u, 0x1c6c6162u, 0x856530d8u, 0xf262004eu,
        0x6c0695edu, 0x1b01a57bu, 0x8208f4c1u, 0xf50fc457u, 0x65b0d9c6u, 0x12b7e950u,
        0x8bbeb8eau, 0xfcb9887cu, 0x62dd1ddfu, 0x15da2d49u, 0x8cd37cf3u, 0xfbd44c65u,
        0x4db26158u, 0x3ab551ceu, 0xa3bc0074u, 0xd4bb30e2u, 0x4adfa541u, 0x3dd895d7u,
        0xa4d1c46du, 0xd3d6f4fbu, 0x4369e96au, 0x346ed9fcu, 0xad678846u, 0xda60b8d0u,
        0x44042d73u, 0x33031de5u, 0xaa0a4c5fu, 0xdd0d7cc9u, 0x5005713cu, 0x270241aau,
        0xbe0b1010u, 0xc90c2086u, 0x5768b525u, 0x206f85b3u, 0xb966d409u, 0xce61e49fu,
        0x5edef90eu, 0x29d9c998u, 0xb0d09822u, 0xc7d7a8b4u, 0x59b33d17u, 0x2eb40d81u,
        0xb7bd5c3bu, 0xc0ba6cadu, 0xedb88320u, 0x9abfb3b6u, 0x03b6e20cu, 0x74b1d29au,
        0xead54739u, 0x9dd277afu, 0x04db2615u, 0x73dc1683u, 0xe3630b12u, 0x94643b84u,
        0x0d6d6a3eu, 0x7a6a5aa8u, 0xe40ecf0bu, 0x9309ff9du, 0x0a00ae27u, 0x7d079eb1u,
        0xf00f9344u, 0x8708a3d2u, 0x1e01f268u, 0x6906c2feu, 0xf762575du, 0x806567cbu,
        0x196c3671u, 0x6e6b06e7u, 0xfed41b76u, 0x89d32be0u, 0x10da7a5au, 0x67dd4accu,
        0xf9b9df6fu, 0x8ebeeff9u, 0x17b7be43u, 0x60b08ed5u, 0xd6d6a3e8u, 0xa1d1937eu,
        0x38d8c2c4u, 0x4fdff252u, 0xd1bb67f1u, 0xa6bc5767u, 0x3fb506ddu, 0x48b2364bu,
        0xd80d2bdau, 0xaf0a1b4cu, 0x36034af6u, 0x41047a60u, 0xdf60efc3u, 0xa867df55u,
        0x316e8eefu, 0x4669be79u, 0xcb61b38cu, 0xbc66831au, 0x256fd2a0u, 0x5268e236u,
        0xcc0c7795u, 0xbb0b4703u, 0x220216b9u, 0x5505262fu, 0xc5ba3bbeu, 0xb2bd0b28u,
        0x2bb45a92u, 0x5cb36a04u, 0xc2d7ffa7u, 0xb5d0cf31u, 0x2cd99e8bu, 0x5bdeae1du,
        0x9b64c2b0u, 0xec63f226u, 0x756aa39cu, 0x026d930au, 0x9c0906a9u, 0xeb0e363fu,
        0x72076785u, 0x05005713u, 0x95bf4a82u, 0xe2b87a14u, 0x7bb12baeu, 0x0cb61b38u,
        0x92d28e9bu, 0xe5d5be0du, 0x7cdcefb7u, 0x0bdbdf21u, 0x86d3d2d4u, 0xf1d4e242u,
        0x68ddb3f8u, 0x1fda836eu, 0x81be16cdu, 0xf6b9265bu, 0x6fb077e1u, 0x18b74777u,
        0x88085ae6u, 0xff0f6a70u, 0x66063bcau, 0x11010b5cu, 0x8f659effu, 0xf862ae69u,
        0x616bffd3u, 0x166ccf45u, 0xa00ae278u, 0xd70dd2eeu, 0x4e048354u, 0x3903b3c2u,
        0xa7672661u, 0xd06016f7u, 0x4969474du, 0x3e6e77dbu, 0xaed16a4au, 0xd9d65adcu,
        0x40df0b66u, 0x37d83bf0u, 0xa9bcae53u, 0xdebb9ec5u, 0x47b2cf7fu, 0x30b5ffe9u,
        0xbdbdf21cu, 0xcabac28au, 0x53b39330u, 0x24b4a3a6u, 0xbad03605u, 0xcdd70693u,
        0x54de5729u, 0x23d967bfu, 0xb3667a2eu, 0xc4614ab8u, 0x5d681b02u, 0x2a6f2b94u,
        0xb40bbe37u, 0xc30c8ea1u, 0x5a05df1bu, 0x2d02ef8du
    },
    {
        0x00000000u, 0x191b3141u, 0x32366282u, 0x2b2d53c3u, 0x646cc504u, 0x7d77f445u,
        0x565aa786u, 0x4f4196c7u, 0xc8d98a08u, 0xd1c2bb49u, 0xfaefe88au, 0xe3f4d9cbu,
        0xacb54f0cu, 0xb5ae7e4du, 0x9e832d8eu, 0x87981ccfu, 0x4ac21251u, 0x53d92310u,
        0x78f470d3u, 0x61ef4192u, 0x2eaed755u, 0x37b5e614u, 0x1c98b5d7u, 0x05838496u,
        0x821b9859u, 0x9b00a918u, 0xb02dfadbu, 0xa936cb9au, 0xe6775d5du, 0xff6c6c1cu,
        0xd4413fdfu, 0xcd5a0e9eu, 0x958424a2u, 0x8c9f15e3u, 0xa7b24620u, 0xbea97761u,
        0xf1e8e1a6u, 0xe8f3d0e7u, 0xc3de8324u, 0xdac5b265u, 0x5d5daeaau, 0x44469febu,
        0x6f6bcc28u, 0x7670fd69u, 0x39316baeu, 0x202a5aefu, 0x0b07092cu, 0x121c386du,
        0xdf4636f3u, 0xc65d07b2u, 0xed705471u, 0xf46b6530u, 0xbb2af3f7u, 0xa231c2b6u,
        0x891c9175u, 0x9007a034u, 0x179fbcfbu, 0x0e848dbau, 0x25a9de79u, 0x3cb2ef38u,
        0x73f379ffu, 0x6ae848beu, 0x41c51b7du, 0x58de2a3cu, 0xf0794f05u, 0xe9627e44u,
        0xc24f2d87u, 0xdb541cc6u, 0x94158a01u, 0x8d0ebb40u, 0xa623e883u, 0xbf38d9c2u,
        0x38a0c50du, 0x21bbf44cu, 0x0a96a78fu, 0x138d96ceu, 0x5ccc0009u, 0x45d73148u,
        0x6efa628bu, 0x77e153cau, 0xbabb5d54u, 0xa3a06c15u, 0x888d3fd6u, 0x91960e97u,
        0xded79850u, 0xc7cca911u, 0xece1fad2u, 0xf5facb93u, 0x7262d75cu, 0x6b79e61du,
        0x4054b5deu, 0x594f849fu, 0x160e1258u, 0x0f152319u, 0x243870dau, 0x3d23419bu,
        0x65fd6ba7u, 0x7ce65ae6u, 0x57cb0925u, 0x4ed03864u, 0x0191aea3u, 0x188a9fe2u,
        0x33a7cc21u, 0x2abcfd60u, 0xad24e1afu, 0xb43fd0eeu, 0x9f12832du, 0x8609b26cu,
        0xc94824abu, 0xd05315eau, 0xfb7e4629u, 0xe2657768u, 0x2f3f79f6u, 0x362448b7u,
        0x1d091b74u, 0x04122a35u, 0x4b53bcf2u, 0x52488db3u, 0x7965de70u, 0x607eef31u,
        0xe7e6f3feu, 0xfefdc2bfu, 0xd5d0917cu, 0xcccba03du, 0x838a36fau, 0x9a9107bbu,
        0xb1bc5478u, 0xa8a76539u, 0x3b83984bu, 0x2298a90au, 0x09b5fac9u, 0x10aecb88u,
        0x5fef5d4fu, 0x46f46c0eu, 0x6dd93fcdu, 0x74c20e8cu, 0xf35a1243u, 0xea412302u,
        0xc16c70c1u, 0xd8774180u, 0x9736d747u, 0x8e2de606u, 0xa500b5c5u, 0xbc1b8484u,
        0x71418a1au, 0x685abb5bu, 0x4377e898u, 0x5a6cd9d9u, 0x152d4f1eu, 0x0c367e5fu,
        0x271b2d9cu, 0x3e001cddu, 0xb9980012u, 0xa0833153u, 0x8bae6290u, 0x92b553d1u,
        0xddf4c516u, 0xc4eff457u, 0xefc2a794u, 0xf6d996d5u, 0xae07bce9u, 0xb71c8da8u,
        0x9c31de6bu, 0x852aef2au, 0xca6b79edu, 0xd37048acu, 0xf85d1b6fu, 0xe1462a2eu,
        0x66de36e1u, 0x7fc507a0u, 0x54e85463u, 0x4df36522u, 0x02b2f3e5u, 0x1ba9c2a4u,
        0x30849167u, 0x299fa026u, 0xe4c5aeb8u, 0xfdde9ff9u, 0xd6f3cc3au, 0xcfe8fd7bu,
        0x80a96bbcu, 0x99b25afdu, 0xb29f093eu, 0xab84387fu, 0x2c1c24b0u, 0x350715f1u,
        0x1e2a4632u, 0x07317773u, 0x4870e1b4u, 0x516bd0f5u, 0x7a468336u, 0x635db277u,
        0xcbfad74eu, 0xd2e1e60fu, 0xf9ccb5ccu, 0xe0d7848du, 0xaf96124au, 0xb68d230bu,
        0x9da070c8u, 0x84bb4189u, 0x03235d46u, 0x1a386c07u, 0x31153fc4u, 0x280e0e85u,
        0x674f9842u, 0x7e54a903u, 0x5579fac0u, 0x4c62cb81u, 0x8138c51fu, 0x9823f45eu,
        0xb30ea79du, 0xaa1596dcu, 0xe554001bu, 0xfc4f315au, 0xd7626299u, 0xce7953d8u,
        0x49e14f17u, 0x50fa7e56u, 0x7bd72d95u, 0x62cc1cd4u, 0x2d8d8a13u, 0x3496bb52u,
        0x1fbbe891u, 0x06a0d9d0u, 0x5e7ef3ecu, 0x4765c2adu, 0x6c48916eu, 0x7553a02fu,
        0x3a1236e8u, 0x230907a9u, 0x0824546au, 0x113f652bu, 0x96a779e4u, 0x8fbc48a5u,
        0xa4911b66u, 0xbd8a2a27u, 0xf2cbbce0u, 0xebd08da1u, 0xc0fdde62u, 0xd9e6ef23u,
        0x14bce1bdu, 0x0da7d0fcu, 0x268a833fu, 0x3f91b27eu, 0x70d024b9u, 0x69cb15f8u,
        0x42e6463bu, 0x5bfd777au, 0xdc656bb5u, 0xc57e5af4u, 0xee530937u, 0xf7483876u,
        0xb809aeb1u, 0xa1129ff0u, 0x8a3fcc33u, 0x9324fd72u
    },
    {
        0x00000000u, 0x01c26a37u, 0x0384d46eu, 0x0246be59u, 0x0709a8dcu, 0x06cbc2ebu,
        0x048d7cb2u, 0x054f1685u, 0x0e1351b8u, 0x0fd13b8fu, 0x0d9785d6u, 0x0c55efe1u,
        0x091af964u, 0x08d89353u, 0x0a9e2d0au, 0x0b5c473du, 0x1c26a370u, 0x1de4c947u,
        0x1fa2771eu, 0x1e601d29u, 0x1b2f0bacu, 0x1aed619bu, 0x18abdfc2u, 0x1969b5f5u,
        0x1235f2c8u, 0x13f798ffu, 0x11b126a6u, 0x10734c91u, 0x153c5a14u, 0x14fe3023u,
        0x16b88e7au, 0x177ae44du, 0x384d46e0u, 0x398f2cd7u, 0x3bc9928eu, 0x3a0bf8b9u,
        0x3f44ee3cu, 0x3e86840bu, 0x3cc03a52u, 0x3d025065u, 0x365e1758u, 0x379c7d6fu,
        0x35dac336u, 0x3418a901u, 0x3157bf84u, 0x3095d5b3u, 0x32d36beau, 0x331101ddu,
        0x246be590u, 0x25a98fa7u, 0x27ef31feu, 0x262d5bc9u, 0x23624d4cu, 0x22a0277bu,
        0x20e69922u, 0x2124f315u, 0x2a78b428u, 0x2bbade1fu, 0x29fc6046u, 0x283e0a71u,
        0x2d711cf4u, 0x2cb376c3u, 0x2ef5c89au, 0x2f37a2adu, 0x709a8dc0u, 0x7158e7f7u,
        0x731e59aeu, 0x72dc3399u, 0x7793251cu, 0x76514f2bu, 0x7417f172u, 0x75d59b45u,
        0x7e89dc78u, 0x7f4bb64fu, 0x7d0d0816u, 0x7ccf6221u, 0x798074a4u, 0x78421e93u,
        0x7a04a0cau, 0x7bc6cafdu, 0x6cbc2eb0u, 0x6d7e4487u, 0x6f38fadeu, 0x6efa90e9u,
        0x6bb5866cu, 0x6a77ec5bu, 0x68315202u, 0x69f33835u, 0x62af7f08u, 0x636d153fu,
        0x612bab66u, 0x60e9c151u, 0x65a6d7d4u, 0x6464bde3u, 0x662203bau, 0x67e0698du,
        0x48d7cb20u, 0x4915a117u, 0x4b531f4eu, 0x4a917579u, 0x4fde63fcu, 0x4e1c09cbu,
        0x4c5ab792u, 0x4d98dda5u, 0x46c49a98u, 0x4706f0afu, 0x45404ef6u, 0x448224c1u,
        0x41cd3244u, 0x400f5873u, 0x4249e62au, 0x438b8c1du, 0x54f16850u, 0x55330267u,
        0x5775bc3eu, 0x56b7d609u, 0x53f8c08cu, 0x523aaabbu, 0x507c14e2u, 0x51be7ed5u,
        0x5ae239e8u, 0x5b2053dfu, 0x5966ed86u, 0x58a487b1u, 0x5deb9134u, 0x5c29fb03u,
        0x5e6f455au, 0x5fad2f6du, 0xe1351b80u, 0xe0f771b7u, 0xe2b1cfeeu, 0xe373a5d9u,
        0xe63cb35cu, 0xe7fed96bu, 0xe5b86732u, 0xe47a0d05u, 0xef264a38u, 0xeee4200fu,
        0xeca29e56u, 0xed60f461u, 0xe82fe2e4u, 0xe9ed88d3u, 0xebab368au, 0xea695cbdu,
        0xfd13b8f0u, 0xfcd1d2c7u, 0xfe976c9eu, 0xff5506a9u, 0xfa1a102cu, 0xfbd87a1bu,
        0xf99ec442u, 0xf85cae75u, 0xf300e948u, 0xf2c2837fu, 0xf0843d26u, 0xf1465711u,
        0xf4094194u, 0xf5cb2ba3u, 0xf78d95fau, 0xf64fffcdu, 0xd9785d60u, 0xd8ba3757u,
        0xdafc890eu, 0xdb3ee339u, 0xde71f5bcu, 0xdfb39f8bu, 0xddf521d2u, 0xdc374be5u,
        0xd76b0cd8u, 0xd6a966efu, 0xd4efd8b6u, 0xd52db281u, 0xd062a404u, 0xd1a0ce33u,
        0xd3e6706au, 0xd2241a5du, 0xc55efe10u, 0xc49c9427u, 0xc6da2a7eu, 0xc7184049u,
        0xc25756ccu, 0xc3953cfbu, 0xc1d382a2u, 0xc011e895u, 0xcb4dafa8u, 0xca8fc59fu,
        0xc8c97bc6u, 0xc90b11f1u, 0xcc440774u, 0xcd866d43u, 0xcfc0d31au, 0xce02b92du,
        0x91af9640u, 0x906dfc77u, 0x922b422eu, 0x93e92819u, 0x96a63e9cu, 0x976454abu,
        0x9522eaf2u, 0x94e080c5u, 0x9fbcc7f8u, 0x9e7eadcfu, 0x9c381396u, 0x9dfa79a1u,
        0x98b56f24u, 0x99770513u, 0x9b31bb4au, 0x9af3d17du, 0x8d893530u, 0x8c4b5f07u,
        0x8e0de15eu, 0x8fcf8b69u, 0x8a809decu, 0x8b42f7dbu, 0x89044982u, 0x88c623b5u,
        0x839a6488u, 0x82580ebfu, 0x801eb0e6u, 0x81dcdad1u, 0x8493cc54u, 0x8551a663u,
        0x8717183au, 0x86d5720du, 0xa9e2d0a0u, 0xa820ba97u, 0xaa6604ceu, 0xaba46ef9u,
        0xaeeb787cu, 0xaf29124bu, 0xad6fac12u, 0xacadc625u, 0xa7f18118u, 0xa633eb2fu,
        0xa4755576u, 0xa5b73f41u, 0xa0f829c4u, 0xa13a43f3u, 0xa37cfdaau, 0xa2be979du,
        0xb5c473d0u, 0xb40619e7u, 0xb640a7beu, 0xb782cd89u, 0xb2cddb0cu, 0xb30fb13bu,
        0xb1490f62u, 0xb08b6555u, 0xbbd72268u, 0xba15485fu, 0xb853f606u, 0xb9919c31u,
        0xbcde8ab4u, 0xbd1ce083u, 0xbf5a5edau, 0xbe9834edu
    },
    {
        0x00000000u, 0xb8bc6765u, 0xaa09c88bu, 0x12b5afeeu, 0x8f629757u, 0x37def032u,
        0x256b5fdcu, 0x9dd738b9u, 0xc5b428efu, 0x7d084f8au, 0x6fbde064u, 0xd7018701u,
        0x4ad6bfb8u, 0xf26ad8ddu, 0xe0df7733u, 0x58631056u, 0x5019579fu, 0xe8a530fau,
        0xfa109f14u, 0x42acf871u, 0xdf7bc0c8u, 0x67c7a7adu, 0x75720843u, 0xcdce6f26u,
        0x95ad7f70u, 0x2d111815u, 0x3fa4b7fbu, 0x8718d09eu, 0x1acfe827u, 0xa2738f42u,
        0xb0c620acu, 0x087a47c9u, 0xa032af3eu, 0x188ec85bu, 0x0a3b67b5u, 0xb28700d0u,
        0x2f503869u, 0x97ec5f0cu, 0x8559f0e2u, 0x3de59787u, 0x658687d1u, 0xdd3ae0b4u,
        0xcf8f4f5au, 0x7733283fu, 0xeae41086u, 0x525877e3u, 0x40edd80du, 0xf851bf68u,
        0xf02bf8a1u, 0x48979fc4u, 0x5a22302au, 0xe29e574fu, 0x7f496ff6u, 0xc7f50893u,
        0xd540a77du, 0x6dfcc018u, 0x359fd04eu, 0x8d23b72bu, 0x9f9618c5u, 0x272a7fa0u,
        0xbafd4719u, 0x0241207cu, 0x10f48f92u, 0xa848e8f7u, 0x9b14583du, 0x23a83f58u,
        0x311d90b6u, 0x89a1f7d3u, 0x1476cf6au, 0xaccaa80fu, 0xbe7f07e1u, 0x06c36084u,
        0x5ea070d2u, 0xe61c17b7u, 0xf4a9b859u, 0x4c15df3cu, 0xd1c2e785u, 0x697e80e0u,
        0x7bcb2f0eu, 0xc377486bu, 0xcb0d0fa2u, 0x73b168c7u, 0x6104c729u, 0xd9b8a04cu,
        0x446f98f5u, 0xfcd3ff90u, 0xee66507eu, 0x56da371bu, 0x0eb9274du, 0xb6054028u,
        0xa4b0efc6u, 0x1c0c88a3u, 0x81dbb01au, 0x3967d77fu, 0x2bd27891u, 0x936e1ff4u,
        0x3b26f703u, 0x839a9066u, 0x912f3f88u, 0x299358edu, 0xb4446054u, 0x0cf80731u,
        0x1e4da8dfu, 0xa6f1cfbau, 0xfe92dfecu, 0x462eb889u, 0x549b1767u, 0xec277002u,
        0x71f048bbu, 0xc94c2fdeu, 0xdbf98030u, 0x6345e755u, 0x6b3fa09cu, 0xd383c7f9u,
        0xc1366817u, 0x798a0f72u, 0xe45d37cbu, 0x5ce150aeu, 0x4e54ff40u, 0xf6e89825u,
        0xae8b8873u, 0x1637ef16u, 0x048240f8u, 0xbc3e279du, 0x21e91f24u, 0x99557841u,
        0x8be0d7afu, 0x335cb0cau, 0xed59b63bu, 0x55e5d15eu, 0x47507eb0u, 0xffec19d5u,
        0x623b216cu, 0xda874609u, 0xc832e9e7u, 0x708e8e82u, 0x28ed9ed4u, 0x9051f9b1u,
        0x82e4565fu, 0x3a58313au, 0xa78f0983u, 0x1f336ee6u, 0x0d86c108u, 0xb53aa66du,
        0xbd40e1a4u, 0x05fc86c1u, 0x1749292fu, 0xaff54e4au, 0x322276f3u, 0x8a9e1196u,
        0x982bbe78u, 0x2097d91du, 0x78f4c94bu, 0xc048ae2eu, 0xd2fd01c0u, 0x6a4166a5u,
        0xf7965e1cu, 0x4f2a3979u, 0x5d9f9697u, 0xe523f1f2u, 0x4d6b1905u, 0xf5d77e60u,
        0xe762d18eu, 0x5fdeb6ebu, 0xc2098e52u, 0x7ab5e937u, 0x680046d9u, 0xd0bc21bcu,
        0x88df31eau, 0x3063568fu, 0x22d6f961u, 0x9a6a9e04u, 0x07bda6bdu, 0xbf01c1d8u,
        0xadb46e36u, 0x15080953u, 0x1d724e9au, 0xa5ce29ffu, 0xb77b8611u, 0x0fc7e174u,
        0x9210d9cdu, 0x2aacbea8u, 0x38191146u, 0x80a57623u, 0xd8c66675u, 0x607a0110u,
        0x72cfaefeu, 0xca73c99bu, 0x57a4f122u, 0xef189647u, 0xfdad39a9u, 0x45115eccu,
        0x764dee06u, 0xcef18963u, 0xdc44268du, 0x64f841e8u, 0xf92f7951u, 0x41931e34u,
        0x5326b1dau, 0xeb9ad6bfu, 0xb3f9c6e9u, 0x0b45a18cu, 0x19f00e62u, 0xa14c6907u,
        0x3c9b51beu, 0x842736dbu, 0x96929935u, 0x2e2efe50u, 0x2654b999u, 0x9ee8defcu,
        0x8c5d7112u, 0x34e11677u, 0xa9362eceu, 0x118a49abu, 0x033fe645u, 0xbb838120u,
        0xe3e09176u, 0x5b5cf613u, 0x49e959fdu, 0xf1553e98u, 0x6c820621u, 0xd43e6144u,
        0xc68bceaau, 0x7e37a9cfu, 0xd67f4138u, 0x6ec3265du, 0x7c7689b3u, 0xc4caeed6u,
        0x591dd66fu, 0xe1a1b10au, 0xf3141ee4u, 0x4ba87981u, 0x13cb69d7u, 0xab770eb2u,
        0xb9c2a15cu, 0x017ec639u, 0x9ca9fe80u, 0x241599e5u, 0x36a0360bu, 0x8e1c516eu,
        0x866616a7u, 0x3eda71c2u, 0x2c6fde2cu, 0x94d3b949u, 0x090481f0u, 0xb1b8e695u,
        0xa30d497bu, 0x1bb12e1eu, 0x43d23e48u, 0xfb6e592du, 0xe9dbf6c3u, 0x516791a6u,
        0xccb0a91fu, 0x740cce7au, 0x66b96194u, 0xde0506f1u
    },
    {
        0x00000000u, 0x3d6029b0u, 0x7ac05360u, 0x47a07ad0u, 0xf580a6c0u, 0xc8e08f70u,
        0x8f40f5a0u, 0xb220dc10u, 0x30704bc1u, 0x0d106271u, 0x4ab018a1u, 0x77d03111u,
        0xc5f0ed01u, 0xf890c4b1u, 0xbf30be61u, 0x825097d1u, 0x60e09782u, 0x5d80be32u,
        0x1a20c4e2u, 0x2740ed52u, 0x95603142u, 0xa80018f2u, 0xefa06222u, 0xd2c04b92u,
        0x5090dc43u, 0x6df0f5f3u, 0x2a508f23u, 0x1730a693u, 0xa5107a83u, 0x98705333u,
        0xdfd029e3u, 0xe2b00053u, 0xc1c12f04u, 0xfca106b4u, 0xbb017c64u, 0x866155d4u,
        0x344189c4u, 0x0921a074u, 0x4e81daa4u, 0x73e1f314u, 0xf1b164c5u, 0xccd14d75u,
        0x8b7137a5u, 0xb6111e15u, 0x0431c205u, 0x3951ebb5u, 0x7ef19165u, 0x4391b8d5u,
        0xa121b886u, 0x9c419136u, 0xdbe1ebe6u, 0xe681c256u, 0x54a11e46u, 0x69c137f6u,
        0x2e614d26u, 0x13016496u, 0x9151f347u, 0xac31daf7u, 0xeb91a027u, 0xd6f18997u,
        0x64d15587u, 0x59b17c37u, 0x1e1106e7u, 0x23712f57u, 0x58f35849u, 0x659371f9u,
        0x22330b29u, 0x1f532299u, 0xad73fe89u, 0x9013d739u, 0xd7b3ade9u, 0xead38459u,
        0x68831388u, 0x55e33a38u, 0x124340e8u, 0x2f236958u, 0x9d03b548u, 0xa0639cf8u,
        0xe7c3e628u, 0xdaa3cf98u, 0x3813cfcbu, 0x0573e67bu, 0x42d39cabu, 0x7fb3b51bu,
        0xcd93690bu, 0xf0f340bbu, 0xb7533a6bu, 0x8a3313dbu, 0x0863840au, 0x3503adbau,
        0x72a3d76au, 0x4fc3fedau, 0xfde322cau, 0xc0830b7au, 0x872371aau, 0xba43581au,
        0x9932774du, 0xa4525efdu, 0xe3f2242du, 0xde920d9du, 0x6cb2d18du, 0x51d2f83du,
        0x167282edu, 0x2b12ab5du, 0xa9423c8cu, 0x9422153cu, 0xd3826fecu, 0xeee2465cu,
        0x5cc29a4cu, 0x61a2b3fcu, 0x2602c92cu, 0x1b62e09cu, 0xf9d2e0cfu, 0xc4b2c97fu,
        0x8312b3afu, 0xbe729a1fu, 0x0c52460fu, 0x31326fbfu, 0x7692156fu, 0x4bf23cdfu,
        0xc9a2ab0eu, 0xf4c282beu, 0xb362f86eu, 0x8e02d1deu, 0x3c220dceu, 0x0142247eu,
        0x46e25eaeu, 0x7b82771eu, 0xb1e6b092u, 0x8c869922u, 0xcb26e3f2u, 0xf646ca42u,
        0x44661652u, 0x79063fe2u, 0x3ea64532u, 0x03c66c82u, 0x8196fb53u, 0xbcf6d2e3u,
        0xfb56a833u, 0xc6368183u, 0x74165d93u, 0x49767423u, 0x0ed60ef3u, 0x33b62743u,
        0xd1062710u, 0xec660ea0u, 0xabc67470u, 0x96a65dc0u, 0x248681d0u, 0x19e6a860u,
        0x5e46d2b0u, 0x6326fb00u, 0xe1766cd1u, 0xdc164561u, 0x9bb63fb1u, 0xa6d61601u,
        0x14f6ca11u, 0x2996e3a1u, 0x6e369971u, 0x5356b0c1u, 0x70279f96u, 0x4d47b626u,
        0x0ae7ccf6u, 0x3787e546u, 0x85a73956u, 0xb8c710e6u, 0xff676a36u, 0xc2074386u,
        0x4057d457u, 0x7d37fde7u, 0x3a978737u, 0x07f7ae87u, 0xb5d77297u, 0x88b75b27u,
        0xcf1721f7u, 0xf2770847u, 0x10c70814u, 0x2da721a4u, 0x6a075b74u, 0x576772c4u,
        0xe547aed4u, 0xd8278764u, 0x9f87fdb4u, 0xa2e7d404u, 0x20b743d5u, 0x1dd76a65u,
        0x5a7710b5u, 0x67173905u, 0xd537e515u, 0xe857cca5u, 0xaff7b675u, 0x92979fc5u,
        0xe915e8dbu, 0xd475c16bu, 0x93d5bbbbu, 0xaeb5920bu, 0x1c954e1bu, 0x21f567abu,
        0x66551d7bu, 0x5b3534cbu, 0xd965a31au, 0xe4058aaau, 0xa3a5f07au, 0x9ec5d9cau,
        0x2ce505dau, 0x11852c6au, 0x562556bau, 0x6b457f0au, 0x89f57f59u, 0xb49556e9u,
        0xf3352c39u, 0xce550589u, 0x7c75d999u, 0x4115f029u, 0x06b58af9u, 0x3bd5a349u,
        0xb9853498u, 0x84e51d28u, 0xc34567f8u, 0xfe254e48u, 0x4c059258u, 0x7165bbe8u,
        0x36c5c138u, 0x0ba5e888u, 0x28d4c7dfu, 0x15b4ee6fu, 0x521494bfu, 0x6f74bd0fu,
        0xdd54611fu, 0xe03448afu, 0xa794327fu, 0x9af41bcfu, 0x18a48c1eu, 0x25c4a5aeu,
        0x6264df7eu, 0x5f04f6ceu, 0xed242adeu, 0xd044036eu, 0x97e479beu, 0xaa84500eu,
        0x4834505du, 0x755479edu, 0x32f4033du, 0x0f942a8du, 0xbdb4f69du, 0x80d4df2du,
        0xc774a5fdu, 0xfa148c4du, 0x78441b9cu, 0x4524322cu, 0x028448fcu, 0x3fe4614cu,
        0x8dc4bd5cu, 0xb0a494ecu, 0xf704ee3cu, 0xca64c78cu
    },
    {
        0x00000000u, 0xcb5cd3a5u, 0x4dc8a10bu, 0x869472aeu, 0x9b914216u, 0x50cd91b3u,
        0xd659e31du, 0x1d0530b8u, 0xec53826du, 0x270f51c8u, 0xa19b2366u, 0x6ac7f0c3u,
        0x77c2c07bu, 0xbc9e13deu, 0x3a0a6170u, 0xf156b2d5u, 0x03d6029bu, 0xc88ad13eu,
        0x4e1ea390u, 0x85427035u, 0x9847408du, 0x531b9328u, 0xd58fe186u, 0x1ed33223u,
        0xef8580f6u, 0x24d95353u, 0xa24d21fdu, 0x6911f258u, 0x7414c2e0u, 0xbf481145u,
        0x39dc63ebu, 0xf280b04eu, 0x07ac0536u, 0xccf0d693u, 0x4a64a43du, 0x81387798u,
        0x9c3d4720u, 0x57619485u, 0xd1f5e62bu, 0x1aa9358eu, 0xebff875bu, 0x20a354feu,
        0xa6372650u, 0x6d6bf5f5u, 0x706ec54du, 0xbb3216e8u, 0x3da66446u, 0xf6fab7e3u,
        0x047a07adu, 0xcf26d408u, 0x49b2a6a6u, 0x82ee7503u, 0x9feb45bbu, 0x54b7961eu,
        0xd223e4b0u, 0x197f3715u, 0xe82985c0u, 0x23755665u, 0xa5e124cbu, 0x6ebdf76eu,
        0x73b8c7d6u, 0xb8e41473u, 0x3e7066ddu, 0xf52cb578u, 0x0f580a6cu, 0xc404d9c9u,
        0x4290ab67u, 0x89cc78c2u, 0x94c9487au, 0x5f959bdfu, 0xd901e971u, 0x125d3ad4u,
        0xe30b8801u, 0x28575ba4u, 0xaec3290au, 0x659ffaafu, 0x789aca17u, 0xb3c619b2u,
        0x35526b1cu, 0xfe0eb8b9u, 0x0c8e08f7u, 0xc7d2db52u, 0x4146a9fcu, 0x8a1a7a59u,
        0x971f4ae1u, 0x5c439944u, 0xdad7ebeau, 0x118b384fu, 0xe0dd8a9au, 0x2b81593fu,
        0xad152b91u, 0x6649f834u, 0x7b4cc88cu, 0xb0101b29u, 0x36846987u, 0xfdd8ba22u,
        0x08f40f5au, 0xc3a8dcffu, 0x453cae51u, 0x8e607df4u, 0x93654d4cu, 0x58399ee9u,
        0xdeadec47u, 0x15f13fe2u, 0xe4a78d37u, 0x2ffb5e92u, 0xa96f2c3cu, 0x6233ff99u,
        0x7f36cf21u, 0xb46a1c84u, 0x32fe6e2au, 0xf9a2bd8fu, 0x0b220dc1u, 0xc07ede64u,
        0x46eaaccau, 0x8db67f6fu, 0x90b34fd7u, 0x5bef9c72u, 0xdd7beedcu, 0x16273d79u,
        0xe7718facu, 0x2c2d5c09u, 0xaab92ea7u, 0x61e5fd02u, 0x7ce0cdbau, 0xb7bc1e1fu,
        0x31286cb1u, 0xfa74bf14u, 0x1eb014d8u, 0xd5ecc77du, 0x5378b5d3u, 0x98246676u,
        0x852156ceu, 0x4e7d856bu, 0xc8e9f7c5u, 0x03b52460u, 0xf2e396b5u, 0x39bf4510u,
        0xbf2b37beu, 0x7477e41bu, 0x6972d4a3u, 0xa22e0706u, 0x24ba75a8u, 0xefe6a60du,
        0x1d661643u, 0xd63ac5e6u, 0x50aeb748u, 0x9bf264edu, 0x86f75455u, 0x4dab87f0u,
        0xcb3ff55eu, 0x006326fbu, 0xf135942eu, 0x3a69478bu, 0xbcfd3525u, 0x77a1e680u,
        0x6aa4d638u, 0xa1f8059du, 0x276c7733u, 0xec30a496u, 0x191c11eeu, 0xd240c24bu,
        0x54d4b0e5u, 0x9f886340u, 0x828d53f8u, 0x49d1805du, 0xcf45f2f3u, 0x04192156u,
        0xf54f9383u, 0x3e134026u, 0xb8873288u, 0x73dbe12du, 0x6eded195u, 0xa5820230u,
        0x2316709eu, 0xe84aa33bu, 0x1aca1375u, 0xd196c0d0u, 0x5702b27eu, 0x9c5e61dbu,
        0x815b5163u, 0x4a0782c6u, 0xcc93f068u, 0x07cf23cdu, 0xf6999118u, 0x3dc542bdu,
        0xbb513013u, 0x700de3b6u, 0x6d08d30eu, 0xa65400abu, 0x20c07205u, 0xeb9ca1a0u,
        0x11e81eb4u, 0xdab4cd11u, 0x5c20bfbfu, 0x977c6c1au, 0x8a795ca2u, 0x41258f07u,
        0xc7b1fda9u, 0x0ced2e0cu, 0xfdbb9cd9u, 0x36e74f7cu, 0xb0733dd2u, 0x7b2fee77u,
        0x662adecfu, 0xad760d6au, 0x2be27fc4u, 0xe0beac61u, 0x123e1c2fu, 0xd962cf8au,
        0x5ff6bd24u, 0x94aa6e81u, 0x89af5e39u, 0x42f38d9cu, 0xc467ff32u, 0x0f3b2c97u,
        0xfe6d9e42u, 0x35314de7u, 0xb3a53f49u, 0x78f9ececu, 0x65fcdc54u, 0xaea00ff1u,
        0x28347d5fu, 0xe368aefau, 0x16441b82u, 0xdd18c827u, 0x5b8cba89u, 0x90d0692cu,
        0x8dd55994u, 0x46898a31u, 0xc01df89fu, 0x0b412b3au, 0xfa1799efu, 0x314b4a4au,
        0xb7df38e4u, 0x7c83eb41u, 0x6186dbf9u, 0xaada085cu, 0x2c4e7af2u, 0xe712a957u,
        0x15921919u, 0xdececabcu, 0x585ab812u, 0x93066bb7u, 0x8e035b0fu, 0x455f88aau,
        0xc3cbfa04u, 0x089729a1u, 0xf9c19b74u, 0x329d48d1u, 0xb4093a7fu, 0x7f55e9dau,
        0x6250d962u, 0xa90c0ac7u, 0x2f987869u, 0xe4c4abccu
    },
    {
        0x00000000u, 0xa6770bb4u, 0x979f1129u, 0x31e81a9du, 0xf44f2413u, 0x52382fa7u,
        0x63d0353au, 0xc5a73e8eu, 0x33ef4e67u, 0x959845d3u, 0xa4705f4eu, 0x020754fau,
        0xc7a06a74u, 0x61d761c0u, 0x503f7b5du, 0xf64870e9u, 0x67de9cceu, 0xc1a9977au,
        0xf0418de7u, 0x56368653u, 0x9391b8ddu, 0x35e6b369u, 0x040ea9f4u, 0xa279a240u,
        0x5431d2a9u, 0xf246d91du, 0xc3aec380u, 0x65d9c834u, 0xa07ef6bau, 0x0609fd0eu,
        0x37e1e793u, 0x9196ec27u, 0xcfbd399cu, 0x69ca3228u, 0x582228b5u, 0xfe552301u,
        0x3bf21d8fu, 0x9d85163bu, 0xac6d0ca6u, 0x0a1a0712u, 0xfc5277fbu, 0x5a257c4fu,
        0x6bcd66d2u, 0xcdba6d66u, 0x081d53e8u, 0xae6a585cu, 0x9f8242c1u, 0x39f54975u,
        0xa863a552u, 0x0e14aee6u, 0x3ffcb47bu, 0x998bbfcfu, 0x5c2c8141u, 0xfa5b8af5u,
        0xcbb39068u, 0x6dc49bdcu, 0x9b8ceb35u, 0x3dfbe081u, 0x0c13fa1cu, 0xaa64f1a8u,
        0x6fc3cf26u, 0xc9b4c492u, 0xf85cde0fu, 0x5e2bd5bbu, 0x440b7579u, 0xe27c7ecdu,
        0xd3946450u, 0x75e36fe4u, 0xb044516au, 0x16335adeu, 0x27db4043u, 0x81ac4bf7u,
        0x77e43b1eu, 0xd19330aau, 0xe07b2a37u, 0x460c2183u, 0x83ab1f0du, 0x25dc14b9u,
        0x14340e24u, 0xb2430590u, 0x23d5e9b7u, 0x85a2e203u, 0xb44af89eu, 0x123df32au,
        0xd79acda4u, 0x71edc610u, 0x4005dc8du, 0xe672d739u, 0x103aa7d0u, 0xb64dac64u,
        0x87a5b6f9u, 0x21d2bd4du, 0xe47583c3u, 0x42028877u, 0x73ea92eau, 0xd59d995eu,
        0x8bb64ce5u, 0x2dc14751u, 0x1c295dccu, 0xba5e5678u, 0x7ff968f6u, 0xd98e6342u,
        0xe86679dfu, 0x4e11726bu, 0xb8590282u, 0x1e2e0936u, 0x2fc613abu, 0x89b1181fu,
        0x4c162691u, 0xea612d25u, 0xdb8937b8u, 0x7dfe3c0cu, 0xec68d02bu, 0x4a1fdb9fu,
        0x7bf7c102u, 0xdd80cab6u, 0x1827f438u, 0xbe50ff8cu, 0x8fb8e511u, 0x29cfeea5u,
        0xdf879e4cu, 0x79f095f8u, 0x48188f65u, 0xee6f84d1u, 0x2bc8ba5fu, 0x8dbfb1ebu,
        0xbc57ab76u, 0x1a20a0c2u, 0x8816eaf2u, 0x2e61e146u, 0x1f89fbdbu, 0xb9fef06fu,
        0x7c59cee1u, 0xda2ec555u, 0xebc6dfc8u, 0x4db1d47cu, 0xbbf9a495u, 0x1d8eaf21u,
        0x2c66b5bcu, 0x8a11be08u, 0x4fb68086u, 0xe9c18b32u, 0xd82991afu, 0x7e5e9a1bu,
        0xefc8763cu, 0x49bf7d88u, 0x78576715u, 0xde206ca1u, 0x1b87522fu, 0xbdf0599bu,
        0x8c184306u, 0x2a6f48b2u, 0xdc27385bu, 0x7a5033efu, 0x4bb82972u, 0xedcf22c6u,
        0x28681c48u, 0x8e1f17fcu, 0xbff70d61u, 0x198006d5u, 0x47abd36eu, 0xe1dcd8dau,
        0xd034c247u, 0x7643c9f3u, 0xb3e4f77du, 0x1593fcc9u, 0x247be654u, 0x820cede0u,
        0x74449d09u, 0xd23396bdu, 0xe3db8c20u, 0x45ac8794u, 0x800bb91au, 0x267cb2aeu,
        0x1794a833u, 0xb1e3a387u, 0x20754fa0u, 0x86024414u, 0xb7ea5e89u, 0x119d553du,
        0xd43a6bb3u, 0x724d6007u, 0x43a57a9au, 0xe5d2712eu, 0x139a01c7u, 0xb5ed0a73u,
        0x840510eeu, 0x22721b5au, 0xe7d525d4u, 0x41a22e60u, 0x704a34fdu, 0xd63d3f49u,
        0xcc1d9f8bu, 0x6a6a943fu, 0x5b828ea2u, 0xfdf58516u, 0x3852bb98u, 0x9e25b02cu,
        0xafcdaab1u, 0x09baa105u, 0xfff2d1ecu, 0x5985da58u, 0x686dc0c5u, 0xce1acb71u,
        0x0bbdf5ffu, 0xadcafe4bu, 0x9c22e4d6u, 0x3a55ef62u, 0xabc30345u, 0x0db408f1u,
        0x3c5c126cu, 0x9a2b19d8u, 0x5f8c2756u, 0xf9fb2ce2u, 0xc813367fu, 0x6e643dcbu,
        0x982c4d22u, 0x3e5b4696u, 0x0fb35c0bu, 0xa9c457bfu, 0x6c636931u, 0xca146285u,
        0xfbfc7818u, 0x5d8b73acu, 0x03a0a617u, 0xa5d7ada3u, 0x943fb73eu, 0x3248bc8au,
        0xf7ef8204u, 0x519889b0u, 0x6070932du, 0xc6079899u, 0x304fe870u, 0x9638e3c4u,
        0xa7d0f959u, 0x01a7f2edu, 0xc400cc63u, 0x6277c7d7u, 0x539fdd4au, 0xf5e8d6feu,
        0x647e3ad9u, 0xc209316du, 0xf3e12bf0u, 0x55962044u, 0x90311ecau, 0x3646157eu,
        0x07ae0fe3u, 0xa1d90457u, 0x579174beu, 0xf1e67f0au, 0xc00e6597u, 0x66796e23u,
        0xa3de50adu, 0x05a95b19u, 0x34414184u, 0x92364a30u
    },
    {
        0x00000000u, 0xccaa009eu, 0x4225077du, 0x8e8f07e3u, 0x844a0efau, 0x48e00e64u,
        0xc66f0987u, 0x0ac50919u, 0xd3e51bb5u, 0x1f4f1b2bu, 0x91c01cc8u, 0x5d6a1c56u,
        0x57af154fu, 0x9b0515d1u, 0x158a1232u, 0xd92012acu, 0x7cbb312bu, 0xb01131b5u,
        0x3e9e3656u, 0xf23436c8u, 0xf8f13fd1u, 0x345b3f4fu, 0xbad438acu, 0x767e3832u,
        0xaf5e2a9eu, 0x63f42a00u, 0xed7b2de3u, 0x21d12d7du, 0x2b142464u, 0xe7be24fau,
        0x69312319u, 0xa59b2387u, 0xf9766256u, 0x35dc62c8u, 0xbb53652bu, 0x77f965b5u,
        0x7d3c6cacu, 0xb1966c32u, 0x3f196bd1u, 0xf3b36b4fu, 0x2a9379e3u, 0xe639797du,
        0x68b67e9eu, 0xa41c7e00u, 0xaed97719u, 0x62737787u, 0xecfc7064u, 0x205670fau,
        0x85cd537du, 0x496753e3u, 0xc7e85400u, 0x0b42549eu, 0x01875d87u, 0xcd2d5d19u,
        0x43a25afau, 0x8f085a64u, 0x562848c8u, 0x9a824856u, 0x140d4fb5u, 0xd8a74f2bu,
        0xd2624632u, 0x1ec846acu, 0x9047414fu, 0x5ced41d1u, 0x299dc2edu, 0xe537c273u,
        0x6bb8c590u, 0xa712c50eu, 0xadd7cc17u, 0x617dcc89u, 0xeff2cb6au, 0x2358cbf4u,
        0xfa78d958u, 0x36d2d9c6u, 0xb85dde25u, 0x74f7debbu, 0x7e32d7a2u, 0xb298d73cu,
        0x3c17d0dfu, 0xf0bdd041u, 0x5526f3c6u, 0x998cf358u, 0x1703f4bbu, 0xdba9f425u,
        0xd16cfd3cu, 0x1dc6fda2u, 0x9349fa41u, 0x5fe3fadfu, 0x86c3e873u, 0x4a69e8edu,
        0xc4e6ef0eu, 0x084cef90u, 0x0289e689u, 0xce23e617u, 0x40ace1f4u, 0x8c06e16au,
        0xd0eba0bbu, 0x1c41a025u, 0x92cea7c6u, 0x5e64a758u, 0x54a1ae41u, 0x980baedfu,
        0x1684a93cu, 0xda2ea9a2u, 0x030ebb0eu, 0xcfa4bb90u, 0x412bbc73u, 0x8d81bcedu,
        0x8744b5f4u, 0x4beeb56au, 0xc561b289u, 0x09cbb217u, 0xac509190u, 0x60fa910eu,
        0xee7596edu, 0x22df9673u, 0x281a9f6au, 0xe4b09ff4u, 0x6a3f9817u, 0xa6959889u,
        0x7fb58a25u, 0xb31f8abbu, 0x3d908d58u, 0xf13a8dc6u, 0xfbff84dfu, 0x37558441u,
        0xb9da83a2u, 0x7570833cu, 0x533b85dau, 0x9f918544u, 0x111e82a7u, 0xddb48239u,
        0xd7718b20u, 0x1bdb8bbeu, 0x95548c5du, 0x59fe8cc3u, 0x80de9e6fu, 0x4c749ef1u,
        0xc2fb9912u, 0x0e51998cu, 0x04949095u, 0xc83e900bu, 0x46b197e8u, 0x8a1b9776u,
        0x2f80b4f1u, 0xe32ab46fu, 0x6da5b38cu, 0xa10fb312u, 0xabcaba0bu, 0x6760ba95u,
        0xe9efbd76u, 0x2545bde8u, 0xfc65af44u, 0x30cfafdau, 0xbe40a839u, 0x72eaa8a7u,
        0x782fa1beu, 0xb485a120u, 0x3a0aa6c3u, 0xf6a0a65du, 0xaa4de78cu, 0x66e7e712u,
        0xe868e0f1u, 0x24c2e06fu, 0x2e07e976u, 0xe2ade9e8u, 0x6c22ee0bu, 0xa088ee95u,
        0x79a8fc39u, 0xb502fca7u, 0x3b8dfb44u, 0xf727fbdau, 0xfde2f2c3u, 0x3148f25du,
        0xbfc7f5beu, 0x736df520u, 0xd6f6d6a7u, 0x1a5cd639u, 0x94d3d1dau, 0x5879d144u,
        0x52bcd85du, 0x9e16d8c3u, 0x1099df20u, 0xdc33dfbeu, 0x0513cd12u, 0xc9b9cd8cu,
        0x4736ca6fu, 0x8b9ccaf1u, 0x8159c3e8u, 0x4df3c376u, 0xc37cc495u, 0x0fd6c40bu,
        0x7aa64737u, 0xb60c47a9u, 0x3883404au, 0xf42940d4u, 0xfeec49cdu, 0x32464953u,
        0xbcc94eb0u, 0x70634e2eu, 0xa9435c82u, 0x65e95c1cu, 0xeb665bffu, 0x27cc5b61u,
        0x2d095278u, 0xe1a352e6u, 0x6f2c5505u, 0xa386559bu, 0x061d761cu, 0xcab77682u,
        0x44387161u, 0x889271ffu, 0x825778e6u, 0x4efd7878u, 0xc0727f9bu, 0x0cd87f05u,
        0xd5f86da9u, 0x19526d37u, 0x97dd6ad4u, 0x5b776a4au, 0x51b26353u, 0x9d1863cdu,
        0x1397642eu, 0xdf3d64b0u, 0x83d02561u, 0x4f7a25ffu, 0xc1f5221cu, 0x0d5f2282u,
        0x079a2b9bu, 0xcb302b05u, 0x45bf2ce6u, 0x89152c78u, 0x50353ed4u, 0x9c9f3e4au,
        0x121039a9u, 0xdeba3937u, 0xd47f302eu, 0x18d530b0u, 0x965a3753u, 0x5af037cdu,
        0xff6b144au, 0x33c114d4u, 0xbd4e1337u, 0x71e413a9u, 0x7b211ab0u, 0xb78b1a2eu,
        0x39041dcdu, 0xf5ae1d53u, 0x2c8e0fffu, 0xe0240f61u, 0x6eab0882u, 0xa201081cu,
        0xa8c40105u, 0x646e019bu, 0xeae10678u, 0x264b06e6u
    }
};

uint32_t vdsh_crc32(uint32_t crc, const void *data, size_t size)
{
    const uint8_t *p = (const uint8_t *)data;
    crc = ~crc;
    while (size >= 8) {
        uint32_t a = get_u32(p) ^ crc;
        uint32_t b = get_u32(p + 4);
        crc = crc_table[7][a & 0xff] ^ crc_table[6][(a >> 8) & 0xff] ^
              crc_table[5][(a >> 16) & 0xff] ^ crc_table[4][a >> 24] ^
              crc_table[3][b & 0xff] ^ crc_table[2][(b >> 8) & 0xff] ^
              crc_table[1][(b >> 16) & 0xff] ^ crc_table[0][b >> 24];
        p += 8;
        size -= 8;
    }
    while (size--)
        crc = crc_table[0][(crc ^ *p++) & 0xff] ^ (crc >> 8);
    return ~crc;
}

/* ------------------------------------------------------------------ */
/* IEEE binary16                                                       */
/* ------------------------------------------------------------------ */

/* Integer-only, so the result does not depend on the FPU's rounding mode
 * or on flush-to-zero settings of whoever calls us. */
uint16_t vdsh_f16_from_f32(float f)
{
    uint32_t x = f32_bits(f);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;

    if (ax > 0x7f800000u) /* NaN: keep the top payload bits, make it quiet */
        return (uint16_t)(sign | 0x7e00u | ((ax >> 13) & 0x3ffu));
    if (ax >= 0x477ff000u) /* >= 65520 rounds to +-Inf (65504 is odd) */
        return (uint16_t)(sign | 0x7c00u);
    if (ax >= 0x38800000u) {
        /* Normal half: rebias the exponent (127 -> 15) and round the 23-bit
         * mantissa to 10 bits, ties to even; a carry out of the mantissa
         * correctly bumps the exponent. */
        uint32_t r = ax - 0x38000000u;
        uint32_t q = r >> 13, rem = r & 0x1fffu;
        if (rem > 0x1000u || (rem == 0x1000u && (q & 1u)))
            q++;
        return (uint16_t)(sign | q);
    }
    if (ax <= 0x33000000u) /* <= 2^-25: rounds to zero (the tie goes to 0) */
        return sign;
    /* Subnormal half: the value in units of 2^-24, rounded to nearest even.
     * 2^-25 < |f| < 2^-14, so the float is normal with exponent 102..112. */
    uint32_t e = ax >> 23;
    uint32_t m = (ax & 0x7fffffu) | 0x800000u;
    uint32_t shift = 126u - e; /* 14 .. 24 */
    uint32_t q = m >> shift, rem = m & ((1u << shift) - 1u);
    uint32_t half = 1u << (shift - 1u);
    if (rem > half || (rem == half && (q & 1u)))
        q++;
    return (uint16_t)(sign | q);
}

float vdsh_f32_from_f16(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16;
    uint32_t e = (h >> 10) & 0x1fu;
    uint32_t m = h & 0x3ffu;
    if (e == 0x1f) /* Inf, NaN (payload and quiet bit kept) */
        return f32_from_bits(sign | 0x7f800000u | (m << 13));
    if (e != 0)
        return f32_from_bits(sign | ((e + 112u) << 23) | (m << 13));
    if (m == 0)
        return f32_from_bits(sign);
    /* Subnormal half: normalise; every one is a normal float. */
    e = 113;
    while (!(m & 0x400u)) {
        m <<= 1;
        e--;
    }
    return f32_from_bits(sign | (e << 23) | ((m & 0x3ffu) << 13));
}

vdsh_result vdsh_encode_f16(const float *src, size_t n, float scale,
                            uint16_t *dst)
{
    if (!(scale > 0.0f) || !isfinite(scale))
        return VDSH_ERR_ARGUMENT;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(src[i]))
            return VDSH_ERR_INVALID;
        uint16_t h = vdsh_f16_from_f32(src[i] / scale);
        if ((h & 0x7c00u) == 0x7c00u)
            return VDSH_ERR_INVALID;
        dst[i] = h;
    }
    return VDSH_OK;
}

/* ------------------------------------------------------------------ */
/* Streams                                                             */
/* ------------------------------------------------------------------ */

const vdsh_stream *vdsh_find_stream(const vdsh_file *f, uint32_t order,
                                    uint32_t quantity)
{
    if (!f || !f->streams)
        return NULL;
    for (uint32_t i = 0; i < f->stream_count; i++)
        if (f->streams[i].order == order &&
            f->streams[i].quantity == quantity)
            return &f->streams[i];
    return NULL;
}

size_t vdsh_stream_bytes_per_vertex(const vdsh_stream *s)
{
    if (!s || s->order < 1 || s->order > VDSH_MAX_ORDER)
        return 0;
    size_t n = (size_t)s->order * s->order;
    if (s->encoding == VDSH_ENCODING_F32)
        return n * 4;
    if (s->encoding == VDSH_ENCODING_F16)
        return n * 2;
    return 0;
}

void vdsh_stream_decode(const vdsh_stream *s, uint32_t v, float *out)
{
    if (s->order < 1 || s->order > VDSH_MAX_ORDER)
        return; /* programmer error; nothing sensible to write */
    uint32_t n = s->order * s->order;
    if (s->encoding == VDSH_ENCODING_F16) {
        const uint16_t *d = (const uint16_t *)s->data + (size_t)v * n;
        for (uint32_t i = 0; i < n; i++)
            out[i] = vdsh_f32_from_f16(d[i]) * s->scale;
    } else if (s->encoding == VDSH_ENCODING_F32) {
        const float *d = (const float *)s->data + (size_t)v * n;
        for (uint32_t i = 0; i < n; i++)
            out[i] = d[i] * s->scale;
    } else {
        for (uint32_t i = 0; i < n; i++)
            out[i] = 0.0f;
    }
}

/* ------------------------------------------------------------------ */
/* Value checks shared by the reader and the writer                   */
/* ------------------------------------------------------------------ */

/* Each returns 1 when the value is acceptable, else 0 with a description
 * in *w. The reader calls them on decoded fields, the writer on the
 * caller's struct: one set of rules, so a written file always reads. */

static int check_header(const vdsh_header *h, why *w)
{
    if (h->vertex_count < 1 || h->vertex_count > VDSH_MAX_VERTICES)
        return bad(w, "HEAD: vertex_count %u out of range 1..%u",
                   h->vertex_count, VDSH_MAX_VERTICES);
    if (h->triangle_count > VDSH_MAX_TRIANGLES)
        return bad(w, "HEAD: triangle_count %u out of range 0..%u",
                   h->triangle_count, VDSH_MAX_TRIANGLES);
    if (h->rays < 1)
        return bad(w, "HEAD: rays is 0, must be at least 1");
    if (h->sampling > VDSH_SAMPLING_HEMISPHERE)
        return bad(w, "HEAD: sampling %u unknown (0 sphere, 1 hemisphere)",
                   h->sampling);
    if (!isfinite(h->max_distance) || !(h->max_distance > 0.0f))
        return bad(w, "HEAD: max_distance %g must be finite and > 0",
                   (double)h->max_distance);
    if (!isfinite(h->max_edge) || !(h->max_edge >= 0.0f))
        return bad(w, "HEAD: max_edge %g must be finite and >= 0",
                   (double)h->max_edge);
    if (h->offset_rule > VDSH_OFFSET_WB_AVG)
        return bad(w, "HEAD: offset_rule %u unknown (0 none, 1 wb-avg)",
                   h->offset_rule);
    if (h->load_flags & ~(uint32_t)VDSH_LOAD_WELD)
        return bad(w, "HEAD: load_flags 0x%x has unknown bits", h->load_flags);
    if (h->trace_flags & ~(uint32_t)VDSH_TRACE_ROBUST)
        return bad(w, "HEAD: trace_flags 0x%x has unknown bits",
                   h->trace_flags);
    for (int k = 0; k < 3; k++) {
        if (!isfinite(h->bounds_min[k]) || !isfinite(h->bounds_max[k]))
            return bad(w, "HEAD: bounds axis %d (%g .. %g) not finite", k,
                       (double)h->bounds_min[k], (double)h->bounds_max[k]);
        if (h->bounds_min[k] > h->bounds_max[k])
            return bad(w, "HEAD: bounds_min[%d] %g > bounds_max[%d] %g", k,
                       (double)h->bounds_min[k], k, (double)h->bounds_max[k]);
    }
    return 1;
}

/* Largest |x| bit pattern of n floats; >= 0x7f800000 means one is Inf or
 * NaN. One pass that vectorises, so the common all-good case is cheap; the
 * slow search for the culprit only runs to word a message. */
static uint32_t max_abs_bits_f32(const float *a, size_t n)
{
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, a + i, sizeof u);
        u &= 0x7fffffffu;
        m = u > m ? u : m;
    }
    return m;
}

static size_t first_nonfinite_f32(const float *a, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(a[i]))
        i++;
    return i;
}

static int check_positions(const float *p, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(p, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(p, n);
        return bad(w, "POSN: vertex %zu has a non-finite coordinate (%g)",
                   i / 3, (double)p[i]);
    }
    return 1;
}

static int check_normals(const float *nrm, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(nrm, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(nrm, n);
        return bad(w, "NORM: normal of vertex %zu has a non-finite component "
                   "(%g)", i / 3, (double)nrm[i]);
    }
    /* |len - 1| < 1e-3 without a square root: compare len^2 against the
     * squared bounds, in double so float rounding cannot move the edge. */
    const double lo = (1.0 - 1e-3) * (1.0 - 1e-3);
    const double hi = (1.0 + 1e-3) * (1.0 + 1e-3);
    for (size_t i = 0; i < v; i++) {
        const float *q = nrm + 3 * i;
        double l2 = (double)q[0] * q[0] + (double)q[1] * q[1] +
                    (double)q[2] * q[2];
        if (!(l2 > lo && l2 < hi) &&
            !(q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f))
            return bad(w, "NORM: normal of vertex %zu (%g, %g, %g) has length "
                       "%g; must be 1 within 1e-3, or exactly (0, 0, 0)", i,
                       (double)q[0], (double)q[1], (double)q[2], sqrt(l2));
    }
    return 1;
}

static int check_indices(const uint32_t *idx, uint32_t t, uint32_t v, why *w)
{
    size_t n = (size_t)t * 3;
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++)
        m = idx[i] > m ? idx[i] : m;
    if (n && m >= v) {
        size_t i = 0;
        while (idx[i] < v)
            i++;
        return bad(w, "TRIS: index %u out of range (%u vertices) in "
                   "triangle %zu", idx[i], v, i / 3);
    }
    return 1;
}

/* Offset of the first byte that breaks strict UTF-8 (no overlong forms,
 * no surrogates, nothing above U+10FFFF), or n when all is well. */
static size_t utf8_error_at(const uint8_t *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        uint32_t c = s[i], cp, min;
        size_t len;
        if (c < 0x80) {
            i++;
            continue;
        } else if ((c & 0xe0) == 0xc0) {
            len = 2, cp = c & 0x1f, min = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            len = 3, cp = c & 0x0f, min = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            len = 4, cp = c & 0x07, min = 0x10000;
        } else {
            return i;
        }
        if (len > n - i)
            return i;
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return i;
            cp = cp << 6 | (s[i + k] & 0x3fu);
        }
        if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return i;
        i += len;
    }
    return n;
}

static int check_name(const uint8_t *name, size_t len, uint32_t i, why *w)
{
    if (len < 1 || len > VDSH_MAX_NAME)
        return bad(w, "SRCS: source %u: name length %zu out of range 1..%d",
                   i, len, VDSH_MAX_NAME);
    if (memchr(name, 0, len))
        return bad(w, "SRCS: source %u: name contains a NUL byte", i);
    size_t at = utf8_error_at(name, len);
    if (at != len)
        return bad(w, "SRCS: source %u: name is not valid UTF-8 (byte %zu)",
                   i, at);
    return 1;
}

/* "COEF order 5 distance": how messages name a stream. */
static void stream_label(const vdsh_stream *s, uint32_t i, char *buf,
                         size_t n)
{
    snprintf(buf, n, "COEF stream %u (order %u, %s)", i, s->order,
             vdsh_quantity_name(s->quantity));
}

static int check_stream(const vdsh_stream *s, uint32_t i, why *w)
{
    char l[96];
    stream_label(s, i, l, sizeof l);
    if (s->order < 1 || s->order > VDSH_MAX_ORDER)
        return bad(w, "%s: order %u out of range 1..%d", l, s->order,
                   VDSH_MAX_ORDER);
    if (s->encoding > VDSH_ENCODING_F16)
        return bad(w, "%s: encoding %u unknown (0 f32, 1 f16)", l,
                   s->encoding);
    /* Any method value is allowed: later bakers add methods, and the
     * coefficients still reconstruct `quantity` (VDSH.md, "Methods"). */
    if (s->quantity > VDSH_QUANTITY_LOG_DISTANCE)
        return bad(w, "%s: quantity %u unknown (0 distance, 1 distance2, "
                   "2 log-distance)", l, s->quantity);
    if (s->window > VDSH_WINDOW_LANCZOS)
        return bad(w, "%s: window %u unknown (0 none, 1 hann, 2 lanczos)", l,
                   s->window);
    if (!isfinite(s->window_param))
        return bad(w, "%s: window_param %g not finite", l,
                   (double)s->window_param);
    if (s->window == VDSH_WINDOW_NONE && s->window_param != 0.0f)
        return bad(w, "%s: window_param %g must be 0 without a window", l,
                   (double)s->window_param);
    if (!isfinite(s->method_param))
        return bad(w, "%s: method_param %g not finite", l,
                   (double)s->method_param);
    if (!isfinite(s->scale) || !(s->scale > 0.0f))
        return bad(w, "%s: scale %g must be finite and > 0", l,
                   (double)s->scale);
    if (s->quantity == VDSH_QUANTITY_LOG_DISTANCE
            ? !(s->quantity_param > 0.0f) || !isfinite(s->quantity_param)
            : s->quantity_param != 0.0f)
        return bad(w, "%s: quantity_param %g must be %s", l, (double)s->quantity_param,
                   s->quantity == VDSH_QUANTITY_LOG_DISTANCE
                       ? "the log floor, finite and > 0" : "0 for this quantity");
    return 1;
}

/* Stored values must be finite, and so must stored * scale, which is what
 * vdsh_stream_decode() hands out (a huge scale could overflow it). */
static int check_stream_data(const vdsh_stream *s, uint32_t i, uint32_t v,
                             why *w)
{
    char l[96];
    size_t nc = (size_t)s->order * s->order;
    size_t n = (size_t)v * nc;
    float maxabs;
    stream_label(s, i, l, sizeof l);
    if (s->encoding == VDSH_ENCODING_F16) {
        const uint16_t *d = (const uint16_t *)s->data;
        uint16_t m = 0;
        for (size_t k = 0; k < n; k++) {
            uint16_t a = (uint16_t)(d[k] & 0x7fffu);
            m = a > m ? a : m;
        }
        if (m >= 0x7c00u) {
            size_t k = 0;
            while ((d[k] & 0x7c00u) != 0x7c00u)
                k++;
            return bad(w, "%s: vertex %zu coefficient %zu is not finite "
                       "(f16 0x%04x)", l, k / nc, k % nc, d[k]);
        }
        maxabs = vdsh_f32_from_f16(m);
    } else {
        const float *d = (const float *)s->data;
        uint32_t m = max_abs_bits_f32(d, n);
        if (m >= 0x7f800000u) {
            size_t k = first_nonfinite_f32(d, n);
            return bad(w, "%s: vertex %zu coefficient %zu is not finite (%g)",
                       l, k / nc, k % nc, (double)d[k]);
        }
        maxabs = f32_from_bits(m);
    }
    if (!isfinite(maxabs * s->scale))
        return bad(w, "%s: a stored value of %g times scale %g overflows a "
                   "float", l, (double)maxabs, (double)s->scale);
    return 1;
}

/* The statistics must describe a bake of vertex_count receivers. */
static int check_stats(const vdsh_stats *t, uint32_t vertex_count, why *w)
{
    if (t->rays_missed > t->rays_traced)
        return bad(w, "stat: %llu rays missed of %llu traced",
                   (unsigned long long)t->rays_missed, (unsigned long long)t->rays_traced);
    const uint32_t v[4] = {t->degenerate_receivers, t->undefined_normals, t->moved_origins,
                           t->flipped_normals};
    static const char *const n[4] = {"degenerate_receivers", "undefined_normals",
                                     "moved_origins", "flipped_normals"};
    for (int k = 0; k < 4; k++)
        if (v[k] > vertex_count)
            return bad(w, "stat: %s %u exceeds the %u receivers", n[k], v[k], vertex_count);
    return 1;
}

static int check_timings(const vdsh_timings *t, why *w)
{
    const double v[5] = {t->load, t->refine, t->build, t->trace, t->total};
    static const char *const n[5] = {"load", "refine", "build", "trace",
                                     "total"};
    for (int k = 0; k < 5; k++)
        if (!isfinite(v[k]) || !(v[k] >= 0.0))
            return bad(w, "time: %s %g must be finite and >= 0", n[k], v[k]);
    return 1;
}

/* ------------------------------------------------------------------ */
/* Reading                                                             */
/* ------------------------------------------------------------------ */

/* One chunk as found by the walk (offsets of the payload in the file). */
typedef struct chunk_ref {
    char id[5];
    uint64_t offset; /* of the chunk header */
    uint64_t size;   /* payload */
} chunk_ref;

enum { WALK_OK, WALK_NO_HEADER, WALK_PAST_END };

/*
 * Look at the chunk whose header starts at `off` (a multiple of 16, at most
 * `size`): fill *c and the stored/computed CRCs. WALK_NO_HEADER when its
 * 16-byte header does not fit, WALK_PAST_END when payload and padding run
 * past `size` (then only the id, size and stored CRC are filled).
 * Every comparison is written as `need > size - have` so nothing can wrap.
 */
static int walk_chunk(const uint8_t *d, size_t size, uint64_t off,
                      chunk_ref *c, uint32_t *crc_stored,
                      uint32_t *crc_computed)
{
    if (CHUNK_HEADER_SIZE > size - off)
        return WALK_NO_HEADER;
    const uint8_t *h = d + off;
    memcpy(c->id, h, 4);
    c->id[4] = 0;
    c->offset = off;
    c->size = get_u64(h + 8);
    *crc_stored = get_u32(h + 4);
    *crc_computed = 0;
    uint64_t room = size - off - CHUNK_HEADER_SIZE;
    if (c->size > room || pad16(c->size) > room - c->size)
        return WALK_PAST_END;
    uint32_t crc = vdsh_crc32(0, h, 4);
    crc = vdsh_crc32(crc, h + 8, 8);
    crc = vdsh_crc32(crc, h + CHUNK_HEADER_SIZE,
                     (size_t)(c->size + pad16(c->size)));
    *crc_computed = crc;
    return WALK_OK;
}

static int is_letter(uint8_t c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

/* The id as it may appear in a message: non-letters shown as '?'. */
static void printable_id(const uint8_t *p, char out[5])
{
    for (int k = 0; k < 4; k++)
        out[k] = is_letter(p[k]) ? (char)p[k] : '?';
    out[4] = 0;
}

/* Everything the validation learnt, so that building the vdsh_file needs
 * no further checks. */
typedef struct layout {
    vdsh_header header;
    uint64_t posn, norm, tris; /* payload offsets */
    uint32_t source_count;
    uint64_t source_name[VDSH_MAX_SOURCES]; /* offsets of the name bytes */
    uint32_t source_name_len[VDSH_MAX_SOURCES];
    uint64_t source_size[VDSH_MAX_SOURCES];
    uint64_t source_sha[VDSH_MAX_SOURCES];
    size_t names_bytes; /* sum of name_length + 1 */
    uint32_t stream_count;
    vdsh_stream streams[VDSH_MAX_STREAMS]; /* data = offset, as an integer */
    uint64_t stream_data[VDSH_MAX_STREAMS];
    int has_stats;
    vdsh_stats stats;
    int has_timings;
    vdsh_timings timings;
} layout;

typedef struct reader {
    const uint8_t *d;
    size_t size;
    const char *name;
    vdsh_error *err;
} reader;

static vdsh_result invalid(const reader *r, const why *w)
{
    return fail(r->err, VDSH_ERR_INVALID, r->name, "%s", w->msg);
}

/* Pass 1: file header, chunk walk, every CRC and padding. */
static vdsh_result read_structure(const reader *r, chunk_ref *chunks,
                                  uint32_t *count)
{
    const uint8_t *d = r->d;
    size_t size = r->size;

    if (size < sizeof vdsh_magic) {
        if (memcmp(d, vdsh_magic, size) != 0)
            return fail(r->err, VDSH_ERR_NOT_VDSH, r->name,
                        "not a .vdsh file (wrong magic)");
        return fail(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);
    }
    if (memcmp(d, vdsh_magic, sizeof vdsh_magic) != 0) {
        if (memcmp(d, vdsh_magic, 4) == 0)
            return fail(r->err, VDSH_ERR_NOT_VDSH, r->name,
                        "not a .vdsh file: magic bytes 4..7 damaged (a "
                        "text-mode transfer changes CR, LF and ^Z)");
        return fail(r->err, VDSH_ERR_NOT_VDSH, r->name,
                    "not a .vdsh file (wrong magic)");
    }
    if (size < FILE_HEADER_SIZE)
        return fail(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);

    /* The version comes before the header CRC: a later version may lay its
     * header out differently, and "unsupported version" is then the useful
     * message. */
    uint32_t version = get_u32(d + 8);
    uint32_t crc_stored = get_u32(d + 28);
    uint32_t crc_computed = vdsh_crc32(0, d, 28);
    if (version != VDSH_FORMAT_VERSION)
        return fail(r->err, VDSH_ERR_VERSION, r->name,
                    "format version %u, this reader reads version %u%s",
                    version, VDSH_FORMAT_VERSION,
                    crc_stored == crc_computed
                        ? ""
                        : " (and the header CRC fails: the file may be "
                          "damaged)");
    if (crc_stored != crc_computed)
        return fail(r->err, VDSH_ERR_CRC, r->name,
                    "header CRC mismatch (stored 0x%08x, computed 0x%08x)",
                    crc_stored, crc_computed);

    uint32_t chunk_count = get_u32(d + 12);
    uint64_t file_size = get_u64(d + 16);
    uint32_t flags = get_u32(d + 24);
    if ((uint64_t)size < file_size)
        return fail(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, the header says %llu", size,
                    (unsigned long long)file_size);
    if ((uint64_t)size > file_size)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "%zu bytes, but the header says %llu (data after the "
                    "end)", size, (unsigned long long)file_size);
    if (flags != 0)
        return fail(r->err, VDSH_ERR_INVALID, r->name,
                    "header flags 0x%x, must be 0", flags);
    if (chunk_count < 1 || chunk_count > MAX_CHUNKS)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "chunk_count %u out of range 1..%d", chunk_count,
                    MAX_CHUNKS);

    uint64_t off = FILE_HEADER_SIZE;
    for (uint32_t i = 0; i < chunk_count; i++) {
        chunk_ref *c = &chunks[i];
        uint32_t cs, cc;
        char pid[5];
        int w = walk_chunk(d, size, off, c, &cs, &cc);
        if (w == WALK_NO_HEADER)
            return fail(r->err, VDSH_ERR_TRUNCATED, r->name,
                        "chunk %u at offset %llu: header runs past the end "
                        "of the file (%u chunks announced)", i,
                        (unsigned long long)off, chunk_count);
        printable_id(d + off, pid);
        if (w == WALK_PAST_END)
            return fail(r->err, VDSH_ERR_TRUNCATED, r->name,
                        "chunk %u '%s' at offset %llu: payload of %llu bytes "
                        "runs past the end of the file", i, pid,
                        (unsigned long long)off,
                        (unsigned long long)c->size);
        if (cs != cc)
            return fail(r->err, VDSH_ERR_CRC, r->name,
                        "chunk %u '%s' at offset %llu: CRC mismatch (stored "
                        "0x%08x, computed 0x%08x)", i, pid,
                        (unsigned long long)off, cs, cc);
        for (int k = 0; k < 4; k++)
            if (!is_letter(d[off + k]))
                return fail(r->err, VDSH_ERR_CHUNK, r->name,
                            "chunk %u at offset %llu: id %02x %02x %02x %02x "
                            "is not four ASCII letters", i,
                            (unsigned long long)off, d[off], d[off + 1],
                            d[off + 2], d[off + 3]);
        uint64_t payload = off + CHUNK_HEADER_SIZE;
        if (!all_zero(d + payload + c->size, (size_t)pad16(c->size)))
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "chunk %u '%s' at offset %llu: padding byte not "
                        "zero", i, pid, (unsigned long long)off);
        off = payload + c->size + pad16(c->size);
    }
    if (off != size)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "%llu bytes after the last of %u chunks",
                    (unsigned long long)(size - off), chunk_count);
    *count = chunk_count;
    return VDSH_OK;
}

static vdsh_result read_head(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    vdsh_header *h = &L->header;
    why w;
    if (c->size != HEAD_SIZE)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "HEAD: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, HEAD_SIZE);
    h->vertex_count = get_u32(p + 0);
    h->triangle_count = get_u32(p + 4);
    h->rays = get_u32(p + 8);
    h->sampling = get_u32(p + 12);
    h->seed = get_u64(p + 16);
    h->max_distance = get_f32(p + 24);
    h->max_edge = get_f32(p + 28);
    h->offset_rule = get_u32(p + 32);
    h->load_flags = get_u32(p + 36);
    h->cube_size = get_u32(p + 40);
    h->occluder_vertex_count = get_u32(p + 44);
    h->occluder_triangle_count = get_u32(p + 48);
    h->trace_flags = get_u32(p + 52);
    for (int k = 0; k < 3; k++) {
        h->bounds_min[k] = get_f32(p + 56 + 4 * k);
        h->bounds_max[k] = get_f32(p + 68 + 4 * k);
    }
    if (!all_zero(p + 80, 48))
        return fail(r->err, VDSH_ERR_INVALID, r->name,
                    "HEAD: reserved bytes 80..127 not zero");
    if (!check_header(h, &w))
        return invalid(r, &w);
    return VDSH_OK;
}

static vdsh_result read_srcs(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    uint64_t n = c->size, off = 4;
    why w;
    if (n < 4)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "SRCS: payload of %llu bytes has no count",
                    (unsigned long long)n);
    uint32_t count = get_u32(p);
    if (count > VDSH_MAX_SOURCES)
        return fail(r->err, VDSH_ERR_INVALID, r->name,
                    "SRCS: count %u out of range 0..%d", count,
                    VDSH_MAX_SOURCES);
    L->names_bytes = 0;
    for (uint32_t i = 0; i < count; i++) {
        if (SOURCE_FIXED_SIZE > n - off)
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "SRCS: source %u runs past the end of the payload",
                        i);
        uint32_t len = get_u32(p + off + 40);
        L->source_sha[i] = c->offset + CHUNK_HEADER_SIZE + off;
        L->source_size[i] = get_u64(p + off + 32);
        off += SOURCE_FIXED_SIZE;
        if (len < 1 || len > VDSH_MAX_NAME)
            return fail(r->err, VDSH_ERR_INVALID, r->name,
                        "SRCS: source %u: name_length %u out of range 1..%d",
                        i, len, VDSH_MAX_NAME);
        uint64_t padded = ((uint64_t)len + 3) & ~(uint64_t)3;
        if (padded > n - off)
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "SRCS: source %u: name runs past the end of the "
                        "payload", i);
        if (!check_name(p + off, len, i, &w))
            return invalid(r, &w);
        if (!all_zero(p + off + len, (size_t)(padded - len)))
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "SRCS: source %u: name padding not zero", i);
        L->source_name[i] = c->offset + CHUNK_HEADER_SIZE + off;
        L->source_name_len[i] = len;
        L->names_bytes += (size_t)len + 1;
        off += padded;
    }
    if (off != n)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "SRCS: %llu bytes after the last source",
                    (unsigned long long)(n - off));
    L->source_count = count;
    return VDSH_OK;
}

/* POSN, NORM and TRIS: 12 bytes per vertex or triangle. */
static vdsh_result read_array(const reader *r, const chunk_ref *c,
                              uint32_t count, const char *what)
{
    if (c->size != (uint64_t)count * 12)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "%s: payload is %llu bytes, %u %s need %llu", c->id,
                    (unsigned long long)c->size, count, what,
                    (unsigned long long)count * 12);
    return VDSH_OK;
}

static vdsh_result read_coef(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    uint32_t i = L->stream_count;
    vdsh_stream *s = &L->streams[i];
    char l[96];
    why w;
    if (i >= VDSH_MAX_STREAMS)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "more than %d COEF chunks", VDSH_MAX_STREAMS);
    if (c->size < STREAM_HEADER_SIZE)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "COEF stream %u: payload of %llu bytes is shorter than "
                    "the %d-byte stream header", i,
                    (unsigned long long)c->size, STREAM_HEADER_SIZE);
    s->order = get_u32(p + 0);
    s->encoding = get_u32(p + 4);
    s->method = get_u32(p + 8);
    s->quantity = get_u32(p + 12);
    s->window = get_u32(p + 16);
    s->window_param = get_f32(p + 20);
    s->method_param = get_f32(p + 24);
    s->scale = get_f32(p + 28);
    s->quantity_param = get_f32(p + 32);
    s->data = NULL;
    stream_label(s, i, l, sizeof l);
    if (!all_zero(p + 36, 12))
        return fail(r->err, VDSH_ERR_INVALID, r->name,
                    "%s: reserved bytes 36..47 not zero", l);
    if (!check_stream(s, i, &w))
        return invalid(r, &w);
    uint64_t need = (uint64_t)L->header.vertex_count * s->order * s->order *
                    (s->encoding == VDSH_ENCODING_F16 ? 2 : 4);
    if (c->size - STREAM_HEADER_SIZE != need)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "%s: %llu bytes of data, %u vertices of %s need %llu", l,
                    (unsigned long long)(c->size - STREAM_HEADER_SIZE),
                    L->header.vertex_count, vdsh_encoding_name(s->encoding),
                    (unsigned long long)need);
    for (uint32_t k = 0; k < i; k++)
        if (L->streams[k].order == s->order &&
            L->streams[k].quantity == s->quantity)
            return fail(r->err, VDSH_ERR_INVALID, r->name,
                        "%s: a second stream for order %u %s (stream %u is "
                        "the first)", l, s->order,
                        vdsh_quantity_name(s->quantity), k);
    s->data = p + STREAM_HEADER_SIZE;
    if (!check_stream_data(s, i, L->header.vertex_count, &w))
        return invalid(r, &w);
    s->data = NULL;
    L->stream_data[i] = c->offset + CHUNK_HEADER_SIZE + STREAM_HEADER_SIZE;
    L->stream_count = i + 1;
    return VDSH_OK;
}

static vdsh_result read_stat(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != STAT_SIZE)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "stat: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, STAT_SIZE);
    L->stats.rays_traced = get_u64(p + 0);
    L->stats.rays_missed = get_u64(p + 8);
    L->stats.degenerate_receivers = get_u32(p + 16);
    L->stats.undefined_normals = get_u32(p + 20);
    L->stats.moved_origins = get_u32(p + 24);
    L->stats.flipped_normals = get_u32(p + 28);
    if (!check_stats(&L->stats, L->header.vertex_count, &w))
        return invalid(r, &w);
    L->has_stats = 1;
    return VDSH_OK;
}

static vdsh_result read_time(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != TIME_SIZE)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "time: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, TIME_SIZE);
    if (!all_zero(p + 44, 20))
        return fail(r->err, VDSH_ERR_INVALID, r->name,
                    "time: reserved bytes 44..63 not zero");
    L->timings.load = get_f64(p + 0);
    L->timings.refine = get_f64(p + 8);
    L->timings.build = get_f64(p + 16);
    L->timings.trace = get_f64(p + 24);
    L->timings.total = get_f64(p + 32);
    L->timings.threads = get_u32(p + 40);
    if (!check_timings(&L->timings, &w))
        return invalid(r, &w);
    L->has_timings = 1;
    return VDSH_OK;
}

/* Pass 2: which chunks, in which numbers, with which contents. */
static vdsh_result read_contents(const reader *r, const chunk_ref *chunks,
                                 uint32_t count, layout *L)
{
    const char *required[4] = {"SRCS", "POSN", "NORM", "TRIS"};
    int seen[4] = {0, 0, 0, 0};
    vdsh_result res;
    why w;

    if (memcmp(chunks[0].id, "HEAD", 4) != 0)
        return fail(r->err, VDSH_ERR_CHUNK, r->name,
                    "chunk 0 is '%s'; HEAD must come first", chunks[0].id);
    if ((res = read_head(r, &chunks[0], L)) != VDSH_OK)
        return res;
    const vdsh_header *h = &L->header;

    for (uint32_t i = 1; i < count; i++) {
        const chunk_ref *c = &chunks[i];
        const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
        int req = -1;
        for (int k = 0; k < 4; k++)
            if (memcmp(c->id, required[k], 4) == 0)
                req = k;
        if (req >= 0 && seen[req]++)
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "chunk %u at offset %llu: a second %s chunk", i,
                        (unsigned long long)c->offset, c->id);

        if (memcmp(c->id, "HEAD", 4) == 0) {
            return fail(r->err, VDSH_ERR_CHUNK, r->name,
                        "chunk %u at offset %llu: a second HEAD chunk", i,
                        (unsigned long long)c->offset);
        } else if (req == 0) {
            res = read_srcs(r, c, L);
        } else if (req == 1) {
            if ((res = read_array(r, c, h->vertex_count, "vertices")) ==
                    VDSH_OK &&
                !check_positions((const float *)p, h->vertex_count, &w))
                res = invalid(r, &w);
            L->posn = c->offset + CHUNK_HEADER_SIZE;
        } else if (req == 2) {
            if ((res = read_array(r, c, h->vertex_count, "vertices")) ==
                    VDSH_OK &&
                !check_normals((const float *)p, h->vertex_count, &w))
                res = invalid(r, &w);
            L->norm = c->offset + CHUNK_HEADER_SIZE;
        } else if (req == 3) {
            if ((res = read_array(r, c, h->triangle_count, "triangles")) ==
                    VDSH_OK &&
                !check_indices((const uint32_t *)p, h->triangle_count,
                               h->vertex_count, &w))
                res = invalid(r, &w);
            L->tris = c->offset + CHUNK_HEADER_SIZE;
        } else if (memcmp(c->id, "COEF", 4) == 0) {
            res = read_coef(r, c, L);
        } else if (memcmp(c->id, "stat", 4) == 0) {
            res = L->has_stats
                      ? fail(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second stat chunk",
                             i, (unsigned long long)c->offset)
                      : read_stat(r, c, L);
        } else if (memcmp(c->id, "time", 4) == 0) {
            res = L->has_timings
                      ? fail(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second time chunk",
                             i, (unsigned long long)c->offset)
                      : read_time(r, c, L);
        } else if (c->id[0] >= 'A' && c->id[0] <= 'Z') {
            res = fail(r->err, VDSH_ERR_CHUNK, r->name,
                       "chunk %u '%s' at offset %llu: unknown critical chunk "
                       "(a newer writer?)", i, c->id,
                       (unsigned long long)c->offset);
        } else {
            res = VDSH_OK; /* unknown ancillary: its CRC was checked; skip */
        }
        if (res != VDSH_OK)
            return res;
    }
    for (int k = 0; k < 4; k++)
        if (!seen[k])
            return fail(r->err, VDSH_ERR_CHUNK, r->name, "no %s chunk",
                        required[k]);
    if (L->stream_count == 0)
        return fail(r->err, VDSH_ERR_CHUNK, r->name, "no COEF chunk");
    return VDSH_OK;
}

static size_t round16(size_t n) { return (n + 15) & ~(size_t)15; }

/*
 * Validate `buf` (which the caller allocated with alloc_file_buffer and
 * hands over: it is owned by the result, or freed on failure) and build
 * the vdsh_file around it.
 */
static vdsh_result load_owned(uint8_t *buf, size_t size, const char *name,
                              vdsh_file **out, vdsh_error *err)
{
    reader r = {buf, size, name ? name : "memory", err};
    chunk_ref chunks[MAX_CHUNKS];
    uint32_t count = 0;
    layout L;
    memset(&L, 0, sizeof L);

    vdsh_result res = read_structure(&r, chunks, &count);
    if (res == VDSH_OK)
        res = read_contents(&r, chunks, count, &L);
    if (res != VDSH_OK) {
        free(buf);
        return res;
    }

    /* One block for the vdsh_file, its stream and source arrays and the
     * names; the file bytes stay in `buf`, which becomes storage_. */
    size_t off_streams = round16(sizeof(vdsh_file));
    size_t off_sources =
        off_streams + round16(L.stream_count * sizeof(vdsh_stream));
    size_t off_names =
        off_sources + round16(L.source_count * sizeof(vdsh_source));
    uint8_t *block = (uint8_t *)calloc(1, off_names + L.names_bytes);
    if (!block) {
        free(buf);
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, r.name,
                    "out of memory (%zu bytes)", off_names + L.names_bytes);
    }
    vdsh_file *f = (vdsh_file *)block;
    f->storage_ = buf;
    f->header = L.header;
    f->positions = (const float *)(buf + L.posn);
    f->normals = (const float *)(buf + L.norm);
    f->indices = (const uint32_t *)(buf + L.tris);

    f->stream_count = L.stream_count;
    f->streams = (vdsh_stream *)(block + off_streams);
    for (uint32_t i = 0; i < L.stream_count; i++) {
        f->streams[i] = L.streams[i];
        f->streams[i].data = buf + L.stream_data[i];
    }

    f->source_count = L.source_count;
    f->sources = L.source_count ? (vdsh_source *)(block + off_sources) : NULL;
    char *names = (char *)(block + off_names);
    for (uint32_t i = 0; i < L.source_count; i++) {
        vdsh_source *s = &f->sources[i];
        memcpy(s->sha256, buf + L.source_sha[i], 32);
        s->size = L.source_size[i];
        s->name = names;
        memcpy(names, buf + L.source_name[i], L.source_name_len[i]);
        names[L.source_name_len[i]] = 0;
        names += L.source_name_len[i] + 1;
    }
    f->has_stats = L.has_stats;
    f->stats = L.stats;
    f->has_timings = L.has_timings;
    f->timings = L.timings;
    *out = f;
    return VDSH_OK;
}

/* 16-byte aligned, as the format's arrays assume; at least 16 bytes so an
 * empty file still gets a buffer. */
static uint8_t *alloc_file_buffer(size_t size)
{
    if (size > SIZE_MAX - 15)
        return NULL;
    return (uint8_t *)aligned_alloc(16, size ? round16(size) : 16);
}

vdsh_result vdsh_read_memory(const void *data, size_t size, const char *name,
                             vdsh_file **out, vdsh_error *err)
{
    const char *nm = name ? name : "memory";
    if (!out || (!data && size))
        return fail(err, VDSH_ERR_ARGUMENT, nm, "vdsh_read_memory: NULL %s",
                    out ? "data" : "out");
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf)
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, nm,
                    "out of memory (%zu bytes)", size);
    if (size)
        memcpy(buf, data, size);
    return load_owned(buf, size, nm, out, err);
}

vdsh_result vdsh_read(const char *path, vdsh_file **out, vdsh_error *err)
{
    if (!path || !out)
        return fail(err, VDSH_ERR_ARGUMENT, path ? path : "(null)",
                    "vdsh_read: NULL %s", path ? "out" : "path");
    /* O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused
     * below, as anything but a regular file); regular files ignore it. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    FILE *fp = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (!fp) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return fail(err, VDSH_ERR_IO, path, "cannot open: %s", strerror(e));
    }
    struct stat st;
    if (fstat(fileno(fp), &st) != 0) {
        int e = errno;
        fclose(fp);
        return fail(err, VDSH_ERR_IO, path, "cannot stat: %s", strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        fclose(fp);
        return fail(err, VDSH_ERR_IO, path, "not a regular file");
    }
    if ((uintmax_t)st.st_size > (uintmax_t)(SIZE_MAX - 15)) {
        fclose(fp);
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, path,
                    "%jd bytes do not fit in memory", (intmax_t)st.st_size);
    }
    size_t size = (size_t)st.st_size;
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf) {
        fclose(fp);
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, path,
                    "out of memory (%zu bytes)", size);
    }
    size_t got = size ? fread(buf, 1, size, fp) : 0;
    int read_error = ferror(fp), e = errno;
    /* A file that changes while it is read (someone writing it in place)
     * would be judged on bytes that no longer exist: refuse. */
    int grew = !read_error && got == size && fgetc(fp) != EOF;
    fclose(fp);
    if (read_error || got != size || grew) {
        free(buf);
        if (read_error)
            return fail(err, VDSH_ERR_IO, path, "read error: %s",
                        strerror(e));
        return fail(err, VDSH_ERR_IO, path,
                    "the file changed size while it was being read");
    }
    return load_owned(buf, size, path, out, err);
}

void vdsh_free(vdsh_file *f)
{
    if (!f)
        return;
    free(f->storage_);
    free(f); /* streams, sources and names live in the same block */
}

/* ------------------------------------------------------------------ */
/* Chunk listing (vdsh-info --verify)                                  */
/* ------------------------------------------------------------------ */

vdsh_result vdsh_scan_chunks(const void *data, size_t size, const char *name,
                             vdsh_chunk_info *out, uint32_t max,
                             uint32_t *count, vdsh_error *err)
{
    const uint8_t *d = (const uint8_t *)data;
    const char *nm = name ? name : "memory";
    if (!count || (!data && size) || (!out && max))
        return fail(err, VDSH_ERR_ARGUMENT, nm, "vdsh_scan_chunks: NULL "
                    "argument");
    if (size && memcmp(d, vdsh_magic,
                       size < sizeof vdsh_magic ? size : sizeof vdsh_magic))
        return fail(err, VDSH_ERR_NOT_VDSH, nm,
                    "not a .vdsh file (wrong magic)");
    if (size < FILE_HEADER_SIZE)
        return fail(err, VDSH_ERR_TRUNCATED, nm,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);
    uint64_t off = FILE_HEADER_SIZE;
    uint32_t n = 0;
    while (off < size && n < UINT32_MAX) {
        chunk_ref c;
        uint32_t cs, cc;
        int w = walk_chunk(d, size, off, &c, &cs, &cc);
        if (w == WALK_NO_HEADER)
            break;
        if (n < max) {
            vdsh_chunk_info *o = &out[n];
            printable_id(d + off, o->id);
            o->complete = w == WALK_OK;
            o->offset = off;
            o->size = c.size;
            o->crc_stored = cs;
            o->crc_computed = cc;
        }
        n++;
        if (w != WALK_OK)
            break;
        off += CHUNK_HEADER_SIZE + c.size + pad16(c.size);
    }
    *count = n;
    return VDSH_OK;
}

/* ------------------------------------------------------------------ */
/* Writing                                                             */
/* ------------------------------------------------------------------ */

/* A chunk to emit: a small encoded prefix (header fields) and the
 * caller's array, both borrowed. */
typedef struct out_chunk {
    char id[4];
    const void *pre;
    size_t pre_size;
    const void *data;
    uint64_t data_size;
    uint32_t crc;
} out_chunk;

typedef struct plan {
    uint8_t file_header[FILE_HEADER_SIZE];
    uint8_t head[HEAD_SIZE];
    uint8_t stream_header[VDSH_MAX_STREAMS][STREAM_HEADER_SIZE];
    uint8_t stat[STAT_SIZE];
    uint8_t time[TIME_SIZE];
    uint8_t *srcs; /* malloc'd SRCS payload */
    out_chunk chunks[MAX_CHUNKS];
    uint32_t count;
    uint64_t file_size;
} plan;

static vdsh_result argument(vdsh_error *err, const char *name, const why *w)
{
    return fail(err, VDSH_ERR_ARGUMENT, name, "not written: %s", w->msg);
}

/* The reader's rules, applied to the caller's struct. */
static vdsh_result check_file(const vdsh_file *f, const char *name,
                              vdsh_error *err)
{
    why w;
    if (!f)
        return fail(err, VDSH_ERR_ARGUMENT, name, "not written: no file");
    const vdsh_header *h = &f->header;
    if (!check_header(h, &w))
        return argument(err, name, &w);
    if (!f->positions || !f->normals || (!f->indices && h->triangle_count))
        return fail(err, VDSH_ERR_ARGUMENT, name,
                    "not written: %s is NULL",
                    !f->positions ? "positions"
                    : !f->normals ? "normals"
                                  : "indices");
    if (!check_positions(f->positions, h->vertex_count, &w) ||
        !check_normals(f->normals, h->vertex_count, &w) ||
        !check_indices(f->indices, h->triangle_count, h->vertex_count, &w))
        return argument(err, name, &w);

    if (f->source_count > VDSH_MAX_SOURCES)
        return fail(err, VDSH_ERR_ARGUMENT, name,
                    "not written: source_count %u out of range 0..%d",
                    f->source_count, VDSH_MAX_SOURCES);
    if (f->source_count && !f->sources)
        return fail(err, VDSH_ERR_ARGUMENT, name,
                    "not written: sources is NULL");
    for (uint32_t i = 0; i < f->source_count; i++) {
        const char *s = f->sources[i].name;
        if (!s)
            return fail(err, VDSH_ERR_ARGUMENT, name,
                        "not written: SRCS: source %u: name is NULL", i);
        if (!check_name((const uint8_t *)s, strnlen(s, VDSH_MAX_NAME + 1), i,
                        &w))
            return argument(err, name, &w);
    }

    if (f->stream_count < 1 || f->stream_count > VDSH_MAX_STREAMS)
        return fail(err, VDSH_ERR_ARGUMENT, name,
                    "not written: stream_count %u out of range 1..%d",
                    f->stream_count, VDSH_MAX_STREAMS);
    if (!f->streams)
        return fail(err, VDSH_ERR_ARGUMENT, name,
                    "not written: streams is NULL");
    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        if (!check_stream(s, i, &w))
            return argument(err, name, &w);
        if (!s->data)
            return fail(err, VDSH_ERR_ARGUMENT, name,
                        "not written: COEF stream %u: data is NULL", i);
        for (uint32_t k = 0; k < i; k++)
            if (f->streams[k].order == s->order &&
                f->streams[k].quantity == s->quantity)
                return fail(err, VDSH_ERR_ARGUMENT, name,
                            "not written: streams %u and %u are both order "
                            "%u %s", k, i, s->order,
                            vdsh_quantity_name(s->quantity));
        if (!check_stream_data(s, i, h->vertex_count, &w))
            return argument(err, name, &w);
    }
    if (f->has_stats && !check_stats(&f->stats, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->has_timings && !check_timings(&f->timings, &w))
        return argument(err, name, &w);
    return VDSH_OK;
}

static void add_chunk(plan *P, const char *id, const void *pre,
                      size_t pre_size, const void *data, uint64_t data_size)
{
    out_chunk *c = &P->chunks[P->count++];
    memcpy(c->id, id, 4);
    c->pre = pre;
    c->pre_size = pre_size;
    c->data = data;
    c->data_size = data_size;
}

static void plan_free(plan *P)
{
    if (P)
        free(P->srcs);
}

/* Validate `f`, encode every header field and compute every CRC. */
static vdsh_result plan_build(plan *P, const vdsh_file *f, const char *name,
                              vdsh_error *err)
{
    memset(P, 0, sizeof *P);
    vdsh_result res = check_file(f, name, err);
    if (res != VDSH_OK)
        return res;
    const vdsh_header *h = &f->header;

    uint8_t *p = P->head;
    put_u32(p + 0, h->vertex_count);
    put_u32(p + 4, h->triangle_count);
    put_u32(p + 8, h->rays);
    put_u32(p + 12, h->sampling);
    put_u64(p + 16, h->seed);
    put_f32(p + 24, h->max_distance);
    put_f32(p + 28, h->max_edge);
    put_u32(p + 32, h->offset_rule);
    put_u32(p + 36, h->load_flags);
    put_u32(p + 40, h->cube_size);
    put_u32(p + 44, h->occluder_vertex_count);
    put_u32(p + 48, h->occluder_triangle_count);
    put_u32(p + 52, h->trace_flags);
    for (int k = 0; k < 3; k++) {
        put_f32(p + 56 + 4 * k, h->bounds_min[k]);
        put_f32(p + 68 + 4 * k, h->bounds_max[k]);
    }
    add_chunk(P, "HEAD", P->head, HEAD_SIZE, NULL, 0);

    /* SRCS is small (at most 64 names of 4096 bytes): encode it whole. */
    size_t srcs_size = 4;
    for (uint32_t i = 0; i < f->source_count; i++)
        srcs_size += SOURCE_FIXED_SIZE +
                     ((strlen(f->sources[i].name) + 3) & ~(size_t)3);
    P->srcs = (uint8_t *)calloc(1, srcs_size);
    if (!P->srcs)
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, name, "out of memory");
    put_u32(P->srcs, f->source_count);
    size_t off = 4;
    for (uint32_t i = 0; i < f->source_count; i++) {
        const vdsh_source *s = &f->sources[i];
        size_t len = strlen(s->name);
        memcpy(P->srcs + off, s->sha256, 32);
        put_u64(P->srcs + off + 32, s->size);
        put_u32(P->srcs + off + 40, (uint32_t)len);
        memcpy(P->srcs + off + SOURCE_FIXED_SIZE, s->name, len);
        off += SOURCE_FIXED_SIZE + ((len + 3) & ~(size_t)3);
    }
    add_chunk(P, "SRCS", P->srcs, srcs_size, NULL, 0);

    uint64_t v = h->vertex_count;
    add_chunk(P, "POSN", NULL, 0, f->positions, v * 12);
    add_chunk(P, "NORM", NULL, 0, f->normals, v * 12);
    add_chunk(P, "TRIS", NULL, 0, f->indices, (uint64_t)h->triangle_count * 12);

    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        p = P->stream_header[i];
        put_u32(p + 0, s->order);
        put_u32(p + 4, s->encoding);
        put_u32(p + 8, s->method);
        put_u32(p + 12, s->quantity);
        put_u32(p + 16, s->window);
        put_f32(p + 20, s->window_param);
        put_f32(p + 24, s->method_param);
        put_f32(p + 28, s->scale);
        put_f32(p + 32, s->quantity_param);
        add_chunk(P, "COEF", p, STREAM_HEADER_SIZE, s->data,
                  v * vdsh_stream_bytes_per_vertex(s));
    }

    if (f->has_stats) {
        p = P->stat;
        put_u64(p + 0, f->stats.rays_traced);
        put_u64(p + 8, f->stats.rays_missed);
        put_u32(p + 16, f->stats.degenerate_receivers);
        put_u32(p + 20, f->stats.undefined_normals);
        put_u32(p + 24, f->stats.moved_origins);
        put_u32(p + 28, f->stats.flipped_normals);
        add_chunk(P, "stat", p, STAT_SIZE, NULL, 0);
    }
    if (f->has_timings) {
        p = P->time;
        put_f64(p + 0, f->timings.load);
        put_f64(p + 8, f->timings.refine);
        put_f64(p + 16, f->timings.build);
        put_f64(p + 24, f->timings.trace);
        put_f64(p + 32, f->timings.total);
        put_u32(p + 40, f->timings.threads);
        add_chunk(P, "time", p, TIME_SIZE, NULL, 0);
    }

    /* Sizes are bounded by the checks above (2^28 vertices, 16 streams of
     * at most 100 bytes per vertex): well inside 64 bits. */
    static const uint8_t zeros[16] = {0};
    uint64_t total = FILE_HEADER_SIZE;
    for (uint32_t i = 0; i < P->count; i++) {
        out_chunk *c = &P->chunks[i];
        uint8_t sz[8];
        uint64_t n = c->pre_size + c->data_size;
        put_u64(sz, n);
        uint32_t crc = vdsh_crc32(0, c->id, 4);
        crc = vdsh_crc32(crc, sz, 8);
        crc = vdsh_crc32(crc, c->pre, c->pre_size);
        crc = vdsh_crc32(crc, c->data, (size_t)c->data_size);
        c->crc = vdsh_crc32(crc, zeros, (size_t)pad16(n));
        total += CHUNK_HEADER_SIZE + n + pad16(n);
    }
    P->file_size = total;

    memcpy(P->file_header, vdsh_magic, 8);
    put_u32(P->file_header + 8, VDSH_FORMAT_VERSION);
    put_u32(P->file_header + 12, P->count);
    put_u64(P->file_header + 16, total);
    put_u32(P->file_header + 24, 0);
    put_u32(P->file_header + 28, vdsh_crc32(0, P->file_header, 28));
    return VDSH_OK;
}

/* Where the bytes go: a buffer of file_size bytes, or a FILE. */
typedef struct sink {
    uint8_t *buf;
    FILE *fp;
    uint64_t pos;
    int error; /* errno of the first failed fwrite */
} sink;

static void sink_put(sink *s, const void *p, uint64_t n)
{
    const uint8_t *b = (const uint8_t *)p;
    if (n == 0 || s->error)
        return;
    if (!s->fp) {
        memcpy(s->buf + s->pos, b, (size_t)n);
        s->pos += n;
        return;
    }
    while (n) {
        size_t k = n > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)n;
        errno = 0;
        if (fwrite(b, 1, k, s->fp) != k) {
            s->error = errno ? errno : EIO;
            return;
        }
        b += k;
        n -= k;
        s->pos += k;
    }
}

static void plan_emit(const plan *P, sink *s)
{
    static const uint8_t zeros[16] = {0};
    sink_put(s, P->file_header, FILE_HEADER_SIZE);
    for (uint32_t i = 0; i < P->count; i++) {
        const out_chunk *c = &P->chunks[i];
        uint8_t hdr[CHUNK_HEADER_SIZE];
        uint64_t n = c->pre_size + c->data_size;
        memcpy(hdr, c->id, 4);
        put_u32(hdr + 4, c->crc);
        put_u64(hdr + 8, n);
        sink_put(s, hdr, CHUNK_HEADER_SIZE);
        sink_put(s, c->pre, c->pre_size);
        sink_put(s, c->data, c->data_size);
        sink_put(s, zeros, pad16(n));
    }
}

vdsh_result vdsh_write_memory(const vdsh_file *f, void **out_data,
                              size_t *out_size, vdsh_error *err)
{
    plan P;
    if (!out_data || !out_size)
        return fail(err, VDSH_ERR_ARGUMENT, "memory",
                    "not written: NULL output pointer");
    vdsh_result res = plan_build(&P, f, "memory", err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }
    if (P.file_size > SIZE_MAX) {
        plan_free(&P);
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, "memory",
                    "%llu bytes do not fit in memory",
                    (unsigned long long)P.file_size);
    }
    uint8_t *buf = (uint8_t *)malloc((size_t)P.file_size);
    if (!buf) {
        plan_free(&P);
        return fail(err, VDSH_ERR_OUT_OF_MEMORY, "memory",
                    "out of memory (%llu bytes)",
                    (unsigned long long)P.file_size);
    }
    sink s = {buf, NULL, 0, 0};
    plan_emit(&P, &s);
    plan_free(&P);
    *out_data = buf;
    *out_size = (size_t)P.file_size;
    return VDSH_OK;
}

vdsh_result vdsh_write(const char *path, const vdsh_file *f, vdsh_error *err)
{
    plan P;
    if (!path)
        return fail(err, VDSH_ERR_ARGUMENT, "(null)",
                    "not written: path is NULL");
    vdsh_result res = plan_build(&P, f, path, err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }

    /* A temporary file beside `path`, renamed over it once complete and
     * on disk (vdsh_output.h). */
    vdsh_output out;
    res = vdsh_output_open(path, &out, err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }
    sink s = {NULL, out.fp, 0, 0};
    plan_emit(&P, &s);
    plan_free(&P);
    if (s.error) {
        res = fail(err, VDSH_ERR_IO, path, "cannot write%s%s: %s",
                   out.tmp ? " temporary file " : "", out.tmp ? out.tmp : "",
                   strerror(s.error));
        vdsh_output_abort(&out);
        return res;
    }
    return vdsh_output_commit(&out, err);
}
