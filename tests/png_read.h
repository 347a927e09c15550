/* A minimal PNG reader for the render tests: 8-bit RGB or RGBA, not interlaced (what gnuplot's png
 * and pngcairo terminals write), decoded with zlib into RGB rows. */
#ifndef PLUME_TEST_PNG_READ_H
#define PLUME_TEST_PNG_READ_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

typedef struct {
    int width, height;
    unsigned char *rgb; /* [3 width height], row-major from the top */
} test_png;

static unsigned png_be32(const unsigned char *p)
{
    return (unsigned)p[0] << 24 | (unsigned)p[1] << 16 | (unsigned)p[2] << 8 | p[3];
}

static int png_paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/* 0 on success (free png->rgb), -1 otherwise. */
static int test_png_read(const char *path, test_png *png)
{
    memset(png, 0, sizeof *png);
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)n), *idat = malloc((size_t)n);
    size_t nidat = 0;
    int ok = buf && idat && fread(buf, 1, (size_t)n, f) == (size_t)n && n > 8 && !memcmp(buf, "\x89PNG\r\n\x1a\n", 8);
    fclose(f);
    int channels = 0;
    for (long at = 8; ok && at + 12 <= n;) {
        unsigned len = png_be32(buf + at);
        const unsigned char *type = buf + at + 4, *data = buf + at + 8;
        if (at + 12 + (long)len > n)
            ok = 0;
        else if (!memcmp(type, "IHDR", 4)) {
            png->width = (int)png_be32(data), png->height = (int)png_be32(data + 4);
            channels = data[9] == 6 ? 4 : data[9] == 2 ? 3 : 0;
            ok = data[8] == 8 && channels && data[12] == 0;
        } else if (!memcmp(type, "IDAT", 4)) {
            memcpy(idat + nidat, data, len);
            nidat += len;
        }
        at += 12 + (long)len;
    }
    unsigned char *raw = NULL;
    size_t stride = (size_t)png->width * (size_t)channels;
    uLongf nraw = (uLongf)((stride + 1) * (size_t)png->height);
    if (ok) {
        raw = malloc(nraw);
        png->rgb = malloc(3 * (size_t)png->width * (size_t)png->height);
        ok = raw && png->rgb && uncompress(raw, &nraw, idat, (uLong)nidat) == Z_OK &&
             nraw == (stride + 1) * (size_t)png->height;
    }
    for (int y = 0; ok && y < png->height; y++) { /* undo the filters in place */
        unsigned char *row = raw + (size_t)y * (stride + 1), *cur = row + 1;
        const unsigned char *up = y ? raw + (size_t)(y - 1) * (stride + 1) + 1 : NULL;
        for (size_t i = 0; i < stride; i++) {
            int a = i >= (size_t)channels ? cur[i - (size_t)channels] : 0, b = up ? up[i] : 0,
                c = up && i >= (size_t)channels ? up[i - (size_t)channels] : 0;
            int pred = row[0] == 0 ? 0 : row[0] == 1 ? a : row[0] == 2 ? b : row[0] == 3 ? (a + b) / 2 : png_paeth(a, b, c);
            cur[i] = (unsigned char)(cur[i] + pred);
        }
        for (int x = 0; x < png->width; x++)
            memcpy(png->rgb + 3 * ((size_t)y * (size_t)png->width + (size_t)x), cur + (size_t)x * (size_t)channels, 3);
    }
    free(buf);
    free(idat);
    free(raw);
    if (!ok) {
        free(png->rgb);
        png->rgb = NULL;
        return -1;
    }
    return 0;
}

#endif
