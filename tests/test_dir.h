/*
 * test_dir.h - counting what a test left in a folder.
 */
#ifndef VDSH_TEST_DIR_H
#define VDSH_TEST_DIR_H

#include <dirent.h>
#include <string.h>

/* How many names in `dir` contain `part` (with part NULL: every name but
 * "." and ".."); -1 when the folder cannot be opened. */
static inline int test_count_names(const char *dir, const char *part)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (part ? strstr(e->d_name, part) != NULL
                 : strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            count++;
    closedir(d);
    return count;
}

#endif
