/*
 * obbtree from C: open a shipped .obbt asset, check it, and run every query on it.
 *
 *   cc -O2 -I bindings/c/include bindings/c/examples/shipped_asset.c \
 *      target/release/libobbtree_c.a -lm -lpthread -ldl -o shipped_asset
 *   ./shipped_asset cow.obbt
 *
 * The tree is opened twice: memory-mapped from its path, and from bytes in memory (as an
 * asset embedded in the executable would be). Model A is the first, model B the second.
 * Every answer is printed on one line, `<query> <pose index> key=value ...`, numbers with
 * 17 significant digits, so that a test can check them against the Rust API.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "obbtree.h"

#define POSES 4

/* Stops the program with the library's message when a call fails. */
static void check(ObbtreeStatus status, const char *what) {
    if (status != OBBTREE_STATUS_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, obbtree_status_name(status),
                obbtree_last_error());
        exit(1);
    }
}

/* A pose: a rotation by `angle` radians about `axis` (0 = x, 1 = y, 2 = z), then a
 * translation. 12 doubles: the rotation row by row, then the translation. */
static void make_pose(int axis, double angle, double tx, double ty, double tz, double pose[12]) {
    double c = cos(angle), s = sin(angle);
    double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    r[i][i] = c;
    r[i][j] = -s;
    r[j][i] = s;
    r[j][j] = c;
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++) pose[3 * row + col] = r[row][col];
    pose[9] = tx;
    pose[10] = ty;
    pose[11] = tz;
}

static void print_numbers(const char *key, const double *values, int n) {
    printf(" %s=", key);
    for (int k = 0; k < n; k++) printf(k ? ",%.17g" : "%.17g", values[k]);
}

static void print_work(const ObbtreeWork *w) {
    printf(" work=%llu,%llu,%llu,%llu,%llu", (unsigned long long)w->bv_disjoint,
           (unsigned long long)w->bv_overlap, (unsigned long long)w->tri_separated,
           (unsigned long long)w->tri_contact, (unsigned long long)w->nodes_visited);
}

/* A witness: its distance, and its points and triangles when it has them. */
static void print_witness(const ObbtreeWitness *w, bool has_pair) {
    printf(" d=%.17g", w->distance);
    if (has_pair) {
        print_numbers("a", w->point_a, 3);
        print_numbers("b", w->point_b, 3);
        printf(" tri=%u,%u", (unsigned)w->tri_a, (unsigned)w->tri_b);
    }
}

static void print_pairs(const char *query, int i, const ObbtreeTrianglePair *pairs, size_t n) {
    printf("%s %d list=", query, i);
    for (size_t k = 0; k < n; k++)
        printf(k ? ",%u,%u" : "%u,%u", (unsigned)pairs[k].tri_a, (unsigned)pairs[k].tri_b);
    printf("\n");
}

/* Reads a whole file into memory (standing in for an asset linked into the program). */
static unsigned char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *bytes = malloc(size > 0 ? (size_t)size : 1);
    if (bytes && fread(bytes, 1, (size_t)size, f) != (size_t)size) {
        free(bytes);
        bytes = NULL;
    }
    fclose(f);
    *len = (size_t)size;
    return bytes;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s FILE.obbt\n", argv[0]);
        return 2;
    }
    printf("version 0 v=%s\n", obbtree_version());

    /* Open: memory-mapped (constant time), then verified once since it came from disk. */
    ObbtreeTree *mapped = NULL;
    check(obbtree_open(argv[1], &mapped), "obbtree_open");
    check(obbtree_verify(mapped), "obbtree_verify");
    ObbtreeInfo info;
    check(obbtree_info(mapped, &info), "obbtree_info");
    printf("info 0 triangles=%u vertices=%u nodes=%u leaves=%u depth=%u leaf_size=%u",
           (unsigned)info.triangles, (unsigned)info.vertices, (unsigned)info.nodes,
           (unsigned)info.leaves, (unsigned)info.depth, (unsigned)info.leaf_size);
    print_numbers("bounds_min", info.bounds_min, 3);
    print_numbers("bounds_max", info.bounds_max, 3);
    printf(" volume=%d precision=%d\n", (int)info.volume, (int)info.precision);
    printf("names 0 volume=%s precision=%s fit=%s encoding=%s\n", info.volume_name,
           info.precision_name, info.fit_name,
           info.encoding_name);

    /* The same tree from bytes in memory: copied into the tree, so freed right away. */
    size_t len = 0;
    unsigned char *bytes = read_file(argv[1], &len);
    if (!bytes) {
        fprintf(stderr, "cannot read %s\n", argv[1]);
        return 1;
    }
    ObbtreeTree *embedded = NULL;
    check(obbtree_open_bytes(bytes, len, &embedded), "obbtree_open_bytes");
    free(bytes);
    ObbtreeInfo info_b;
    check(obbtree_info(embedded, &info_b), "obbtree_info");
    printf("embedded 0 triangles=%u file_bytes=%llu\n", (unsigned)info_b.triangles,
           (unsigned long long)info_b.file_bytes);

    /* Poses: A once, B at POSES places (touching, turned, apart, far and turned). */
    double pose_a[12], poses_b[POSES][12];
    make_pose(2, 0.1, 0.01, 0.02, 0.03, pose_a);
    make_pose(2, 0.0, 0.3, 0.0, 0.0, poses_b[0]);
    make_pose(2, 0.5, 0.1, 0.05, 0.0, poses_b[1]);
    make_pose(1, 0.0, 2.0, 0.0, 0.0, poses_b[2]);
    make_pose(1, 1.0, 0.0, 1.5, 0.2, poses_b[3]);
    printf("pose_a 0");
    print_numbers("p", pose_a, 12);
    printf("\n");
    for (int i = 0; i < POSES; i++) {
        printf("pose_b %d", i);
        print_numbers("p", poses_b[i], 12);
        printf("\n");
    }

    /* One pose pair per call through a pair handle (one per thread). */
    const double rel_err = 0.1, max_distance = 0.5, tolerance = 0.05;
    ObbtreePair *pair = NULL;
    check(obbtree_pair_new(mapped, embedded, &pair), "obbtree_pair_new");
    for (int i = 0; i < POSES; i++) {
        const double *pose_b = poses_b[i];

        /* All contacts: ask for the count, then for the pairs into a buffer that fits. */
        ObbtreeCollideResult c;
        check(obbtree_pair_collide(pair, pose_a, pose_b, false, NULL, 0, &c), "collide");
        ObbtreeTrianglePair *pairs = malloc((c.pair_count ? c.pair_count : 1) * sizeof *pairs);
        check(obbtree_pair_collide(pair, pose_a, pose_b, false, pairs, c.pair_count, &c),
              "collide");
        printf("collide %d colliding=%d contacts=%zu", i, (int)c.colliding, c.pair_count);
        print_work(&c.work);
        printf("\n");
        print_pairs("pairs", i, pairs, c.pair_count);
        free(pairs);

        /* First contact: a yes/no answer with one witness pair. */
        ObbtreeTrianglePair first;
        check(obbtree_pair_collide(pair, pose_a, pose_b, true, &first, 1, &c), "first contact");
        printf("first %d colliding=%d contacts=%zu", i, (int)c.colliding, c.pair_count);
        if (c.pair_count) printf(" pair=%u,%u", (unsigned)first.tri_a, (unsigned)first.tri_b);
        printf("\n");

        /* Distance: exact, within 10%, and only if under 0.5 apart. */
        ObbtreeDistanceResult d;
        check(obbtree_pair_distance(pair, pose_a, pose_b, 0.0, 0.0, INFINITY, &d), "distance");
        printf("distance %d found=%d", i, (int)d.found);
        print_witness(&d.closest, d.found);
        print_work(&d.work);
        printf("\n");
        check(obbtree_pair_distance(pair, pose_a, pose_b, rel_err, 0.0, INFINITY, &d),
              "distance");
        printf("distance_rel %d rel_err=%.17g found=%d", i, rel_err, (int)d.found);
        print_witness(&d.closest, d.found);
        printf("\n");
        check(obbtree_pair_distance(pair, pose_a, pose_b, 0.0, 0.0, max_distance, &d),
              "distance");
        printf("distance_max %d max_distance=%.17g found=%d", i, max_distance, (int)d.found);
        print_witness(&d.closest, d.found);
        printf("\n");

        /* Tolerance: closer than 0.05? */
        ObbtreeToleranceResult t;
        check(obbtree_pair_within(pair, pose_a, pose_b, tolerance, &t), "within");
        printf("within %d tolerance=%.17g closer=%d", i, tolerance, (int)t.closer);
        print_witness(&t.witness, t.closer);
        printf("\n");

        /* Span: the largest distance between the two models. */
        ObbtreeSpanResult s;
        check(obbtree_pair_span(pair, pose_a, pose_b, &s), "span");
        printf("span %d", i);
        print_witness(&s.farthest, true);
        printf("\n");
    }
    obbtree_pair_free(pair);

    /* Batches: A's one pose against all of B's (broadcast), in parallel on 2 threads. */
    ObbtreeCollideResult collisions[POSES];
    size_t total = 0;
    check(obbtree_collide_batch(mapped, pose_a, 1, embedded, &poses_b[0][0], POSES, false, 2,
                                collisions, POSES, NULL, 0, &total),
          "collide batch (count)");
    ObbtreeTrianglePair *all = malloc((total ? total : 1) * sizeof *all);
    check(obbtree_collide_batch(mapped, pose_a, 1, embedded, &poses_b[0][0], POSES, false, 2,
                                collisions, POSES, all, total, &total),
          "collide batch");
    for (int i = 0; i < POSES; i++) {
        printf("batch_collide %d colliding=%d contacts=%zu offset=%zu\n", i,
               (int)collisions[i].colliding, collisions[i].pair_count,
               collisions[i].pair_offset);
        print_pairs("batch_pairs", i, all + collisions[i].pair_offset, collisions[i].pair_count);
    }
    free(all);

    ObbtreeDistanceResult distances[POSES];
    check(obbtree_distance_batch(mapped, pose_a, 1, embedded, &poses_b[0][0], POSES, 0.0, 0.0,
                                 INFINITY, 2, distances, POSES),
          "distance batch");
    ObbtreeToleranceResult tolerances[POSES];
    check(obbtree_within_batch(mapped, pose_a, 1, embedded, &poses_b[0][0], POSES, tolerance, 2,
                               tolerances, POSES),
          "within batch");
    ObbtreeSpanResult spans[POSES];
    check(obbtree_span_batch(mapped, pose_a, 1, embedded, &poses_b[0][0], POSES, 2, spans,
                             POSES),
          "span batch");
    for (int i = 0; i < POSES; i++) {
        printf("batch_distance %d found=%d", i, (int)distances[i].found);
        print_witness(&distances[i].closest, distances[i].found);
        printf("\nbatch_within %d tolerance=%.17g closer=%d", i, tolerance,
               (int)tolerances[i].closer);
        print_witness(&tolerances[i].witness, tolerances[i].closer);
        printf("\nbatch_span %d", i);
        print_witness(&spans[i].farthest, true);
        printf("\n");
    }

    /* Errors are codes plus a message: a scaled rotation is not a pose. */
    double scaled[12];
    memcpy(scaled, pose_a, sizeof scaled);
    scaled[0] *= 2.0;
    ObbtreeStatus status = obbtree_pose_check(scaled);
    printf("error 0 %s: %s\n", obbtree_status_name(status), obbtree_last_error());

    obbtree_close(embedded);
    obbtree_close(mapped);
    return 0;
}
