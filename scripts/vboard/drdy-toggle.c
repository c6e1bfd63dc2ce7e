/* drdy-toggle: drives a gpio-sim line like the ADS131M06's data-ready output, for the virtual
 * board (scripts/vboard). Built static on the host (gcc -static) and run inside the QEMU VM.
 *
 *   drdy-toggle PULL_FILE RATE_HZ [COUNT]
 *
 * PULL_FILE is gpio-sim's /sys/devices/platform/<dev>/<chip>/sim_gpioN/pull; writing "pull-up"
 * raises the simulated input, "pull-down" lowers it, and the kernel delivers the edge to a
 * process holding the line (gpiomon, the firmware) with a CLOCK_MONOTONIC timestamp. The line
 * behaves like the ADS131M06's DRDY output, which is active low (datasheet, DRDY pin: the
 * high-to-low transition marks new data, falling edges are one data-rate period apart): it idles
 * high, falls at each deadline (one per period 1/RATE_HZ, absolute deadlines with
 * clock_nanosleep TIMER_ABSTIME so the rate does not drift with the time a write takes) and
 * rises again half a period later. RATE_HZ 0 toggles as fast as possible (to measure what the VM
 * reaches). COUNT 0 or absent: until SIGTERM/SIGINT.
 *
 * Like a real ADC whose host stalls, a deadline missed by more than one period is not caught up
 * in a burst: the schedule restarts from now and the skipped periods are counted (SIGSTOP then
 * SIGCONT therefore looks like data-ready edges stopped and restarted). On exit it prints one
 * line: "drdy-toggle: edges=N skipped=S late=L irregular=I seconds=T rate_hz=R" (late: falling
 * edges written more than a quarter period after their deadline; irregular: an upper bound on
 * the edges a receiver that infers gaps from the kernel's edge timestamps may count as missed
 * although the toggler wrote them, see below); SIGUSR1 prints the same line at once, so a
 * script can read the counts while the toggler runs.
 *
 * Why "irregular": the kernel stamps an edge somewhere inside its pwrite, [before, after] as
 * read from CLOCK_MONOTONIC around the call. A receiver that takes round(dt / period) - 1 as the
 * edges missed between two stamps (the firmware's data-ready driver does) can see at most
 * round((after_k - before_{k-1}) / period) - 1 of them at edge k; on a VM under load a write
 * that lands more than half a period late shows up that way. The sum of those bounds is what a
 * test may allow the firmware to report while the toggler itself dropped nothing.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static volatile sig_atomic_t stop_requested;
static volatile sig_atomic_t report_requested;
static void on_signal(int sig) {
  if (sig == SIGUSR1) {
    report_requested = 1;
  } else {
    stop_requested = 1;
  }
}

static int64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static void sleep_until(int64_t t_ns) {
  struct timespec ts = {.tv_sec = (time_t)(t_ns / 1000000000LL),
                        .tv_nsec = (long)(t_ns % 1000000000LL)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR && !stop_requested) {
  }
}

static void report(long long edges, long long skipped, long long late, long long irregular,
                   int64_t t0) {
  const double seconds = (double)(now_ns() - t0) * 1e-9;
  printf("drdy-toggle: edges=%lld skipped=%lld late=%lld irregular=%lld seconds=%.3f rate_hz=%.1f\n",
         edges, skipped, late, irregular, seconds, seconds > 0 ? (double)edges / seconds : 0.0);
  fflush(stdout);
}

static int write_pull(int fd, const char* value, const char* path) {
  if (pwrite(fd, value, strlen(value), 0) < 0) {
    fprintf(stderr, "drdy-toggle: writing '%s' to %s: %s\n", value, path, strerror(errno));
    return -1;
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    fprintf(stderr, "usage: drdy-toggle PULL_FILE RATE_HZ [COUNT]\n");
    return 2;
  }
  const char* path = argv[1];
  char* end = NULL;
  const double rate_hz = strtod(argv[2], &end);
  if (*end != '\0' || rate_hz < 0.0 || rate_hz > 100000.0) {
    fprintf(stderr, "drdy-toggle: RATE_HZ '%s' must be a number 0..100000\n", argv[2]);
    return 2;
  }
  long long count = 0;
  if (argc == 4) {
    count = strtoll(argv[3], &end, 10);
    if (*end != '\0' || count < 0) {
      fprintf(stderr, "drdy-toggle: COUNT '%s' must be a non-negative integer\n", argv[3]);
      return 2;
    }
  }
  const int fd = open(path, O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    fprintf(stderr, "drdy-toggle: cannot open %s: %s\n", path, strerror(errno));
    return 1;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);

  const int64_t period_ns = rate_hz > 0.0 ? (int64_t)(1e9 / rate_hz + 0.5) : 0;
  if (write_pull(fd, "pull-up", path) != 0) return 1; /* idle: DRDY high, no data */
  const int64_t t0 = now_ns();
  int64_t next = t0 + period_ns;
  long long edges = 0, skipped = 0, late = 0, irregular = 0;
  int64_t before_previous = -1; /* CLOCK_MONOTONIC just before the previous falling-edge write */
  while (!stop_requested && (count == 0 || edges < count)) {
    if (report_requested) {
      report_requested = 0;
      report(edges, skipped, late, irregular, t0);
    }
    if (period_ns > 0) {
      sleep_until(next);
      if (stop_requested) break;
      const int64_t lag = now_ns() - next;
      if (lag > period_ns) { /* stalled: restart the schedule, count what was skipped */
        skipped += lag / period_ns;
        next += (lag / period_ns) * period_ns;
      }
    }
    const int64_t before = now_ns();
    if (write_pull(fd, "pull-down", path) != 0) return 1; /* falling edge: new data */
    const int64_t after = now_ns();
    ++edges;
    if (period_ns > 0) {
      if (after - next > period_ns / 4) ++late;
      if (before_previous >= 0) {
        const int64_t k = (after - before_previous + period_ns / 2) / period_ns;
        if (k > 1) irregular += k - 1;
      }
      before_previous = before;
      sleep_until(next + period_ns / 2);
    }
    if (write_pull(fd, "pull-up", path) != 0) return 1;
    next += period_ns;
  }
  report(edges, skipped, late, irregular, t0);
  close(fd);
  return 0;
}
