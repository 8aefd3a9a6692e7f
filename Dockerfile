# thirdbody: the HTTP service in a container.
#
#   docker build -t thirdbody --build-arg THIRDBODY_GIT_COMMIT=$(git rev-parse --short=12 HEAD) .
#   docker run --rm -p 8080:8080 thirdbody
#
# Build stage: the same toolchain as CI, dependencies fetched by cargo (crates.io only; the
# API docs assets are vendored in a crate, nothing is downloaded at run time).
FROM rust:1.95-slim-bookworm AS build
# The commit every answer names (meta.software.commit): .git is not in the build context.
ARG THIRDBODY_GIT_COMMIT=unknown
ENV THIRDBODY_GIT_COMMIT=${THIRDBODY_GIT_COMMIT}
WORKDIR /src
COPY Cargo.toml Cargo.lock build.rs ./
COPY model model
COPY src src
COPY benches benches
COPY openapi openapi
RUN cargo build --release --locked --bin thirdbody

# Run stage: the binary alone, as an unprivileged user.
FROM debian:bookworm-slim
# The database of saved analyses lives in a volume (a single service keeps its history
# there across restarts; a fleet keeps it in Redis and leaves the volume empty).
RUN useradd --system --uid 10001 --no-create-home thirdbody \
    && mkdir -p /var/lib/thirdbody && chown thirdbody /var/lib/thirdbody
VOLUME /var/lib/thirdbody
COPY --from=build /src/target/release/thirdbody /usr/local/bin/thirdbody
USER thirdbody
# Every setting is a flag with an environment variable (`thirdbody serve --help`); these are
# the ones a container needs: listen on all interfaces, JSON logs for the log collector, the
# database in the volume, and a shutdown bound below the orchestrator's grace period
# (deploy/base/deployment.yaml: 40 s).
ENV THIRDBODY_BIND=0.0.0.0:8080 \
    THIRDBODY_LOG_FORMAT=json \
    THIRDBODY_DATABASE=/var/lib/thirdbody/thirdbody.db \
    THIRDBODY_SHUTDOWN_TIMEOUT=25s
EXPOSE 8080
# Alive when /healthz answers on THIRDBODY_BIND. `thirdbody worker` serves no API: it answers
# /healthz, /readyz and /metrics only on THIRDBODY_METRICS_BIND (--metrics-bind), so its
# compose service sets 0.0.0.0:9100 and checks `thirdbody healthcheck --bind 127.0.0.1:9100`.
HEALTHCHECK --interval=10s --timeout=3s --start-period=5s --retries=3 CMD ["thirdbody", "healthcheck"]
# SIGTERM drains: /readyz turns 503, in-flight requests and running jobs finish, then exit.
STOPSIGNAL SIGTERM
ENTRYPOINT ["thirdbody"]
CMD ["serve"]
