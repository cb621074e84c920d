//! Merging the triangle primitives of every placed mesh into one indexed mesh: vertices in
//! traversal order then accessor order, strips and fans turned into triangles.

use ::gltf::json::mesh::{Mode, Semantic};
use ::gltf::json::validation::Checked;
use ::gltf::json::Root;

use super::super::{Format, LoadError, Location};
use std::borrow::Cow;

use super::accessor::{layout, load_buffers, read_indices, read_vectors, Layout};
use super::meshopt::Compression;
use super::scene::{determinant3, transform_point, Instance, IDENTITY};
use crate::mesh::Mesh;

/// Caps on the merged mesh. Each accessor is backed by bytes of the file, but nodes may place
/// one mesh many times, so the total is bounded separately; these sit far above any
/// segmentation surface (millions of triangles) and keep a hostile file from exhausting memory.
const MAX_VERTICES: u64 = 1 << 25;
const MAX_TRIANGLES: u64 = 1 << 26;

/// One triangle primitive of one placed mesh, with its accessors resolved.
struct Job<'a> {
    instance: &'a Instance,
    mode: Mode,
    positions: Layout,
    indices: Option<Layout>,
}

fn triangle_mode(mode: Mode) -> bool {
    matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    )
}

/// Upper bound of the triangles `n` vertex references make in `mode`.
fn max_triangles(mode: Mode, n: usize) -> u64 {
    match mode {
        Mode::Triangles => (n / 3) as u64,
        _ => n.saturating_sub(2) as u64,
    }
}

pub(super) fn merge(
    root: &Root,
    compression: &Compression,
    instances: &[Instance],
    bin: Option<&[u8]>,
    format: Format,
) -> Result<Mesh, LoadError> {
    let jobs = plan(root, compression, instances, format)?;
    let needed = check_totals(compression.buffer_count(), &jobs, format)?;
    let buffers = load_buffers(root, compression, bin, &needed, format)?;
    assemble(&jobs, &buffers, format)
}

/// [`merge`] with every buffer already loaded (a reader that merges node by node).
pub(super) fn merge_loaded(
    root: &Root,
    compression: &Compression,
    instances: &[Instance],
    buffers: &[Option<Cow<[u8]>>],
    format: Format,
) -> Result<Mesh, LoadError> {
    let jobs = plan(root, compression, instances, format)?;
    check_totals(buffers.len(), &jobs, format)?;
    assemble(&jobs, buffers, format)
}

/// Refuses totals past the caps; returns which buffers the jobs read.
fn check_totals(buffers: usize, jobs: &[Job], format: Format) -> Result<Vec<bool>, LoadError> {
    let mut vertex_total = 0u64;
    let mut triangle_total = 0u64;
    let mut needed = vec![false; buffers];
    for job in jobs {
        vertex_total = vertex_total.saturating_add(job.positions.count as u64);
        let refs = job.indices.as_ref().unwrap_or(&job.positions).count;
        triangle_total = triangle_total.saturating_add(max_triangles(job.mode, refs));
        for l in std::iter::once(&job.positions).chain(&job.indices) {
            if let Some(flag) = needed.get_mut(l.buffer) {
                *flag = true;
            }
        }
    }
    for (what, claimed, possible) in [
        ("vertices", vertex_total, MAX_VERTICES),
        ("triangles", triangle_total, MAX_TRIANGLES),
    ] {
        if claimed > possible {
            return Err(LoadError::CountTooLarge {
                format,
                what,
                claimed,
                possible,
            });
        }
    }
    Ok(needed)
}

fn assemble(
    jobs: &[Job],
    buffers: &[Option<Cow<[u8]>>],
    format: Format,
) -> Result<Mesh, LoadError> {
    let vertex_total: usize = jobs.iter().map(|j| j.positions.count).sum();
    let triangle_total: u64 = jobs
        .iter()
        .map(|j| max_triangles(j.mode, j.indices.as_ref().unwrap_or(&j.positions).count))
        .sum();
    let data = |l: &Layout| {
        buffers
            .get(l.buffer)
            .and_then(|b| b.as_deref())
            .ok_or_else(|| LoadError::Syntax {
                format,
                location: Location::Item("buffer", l.buffer),
                detail: "was not loaded".into(),
            })
    };

    // Both totals are bounded by the caps above.
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(vertex_total);
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(triangle_total as usize);
    for job in jobs {
        let points = placed_points(job, data(&job.positions)?, format)?;
        let refs = vertex_refs(job, points.len(), &data, format)?;
        let base = positions.len() as u32;
        let mirrored = determinant3(&job.instance.matrix) < 0.0;
        let mut push = |t: [u32; 3]| {
            let [a, b, c] = t.map(|v| v + base);
            // A mirroring transform turns counter-clockwise into clockwise: swap to undo it.
            triangles.push(if mirrored { [a, c, b] } else { [a, b, c] });
        };
        match job.mode {
            Mode::Triangles => refs.chunks_exact(3).for_each(|t| push([t[0], t[1], t[2]])),
            Mode::TriangleStrip => {
                for (i, w) in refs.windows(3).enumerate() {
                    let t = if i % 2 == 0 {
                        [w[0], w[1], w[2]]
                    } else {
                        [w[0], w[2], w[1]]
                    };
                    push_unless_repeated(&mut push, t);
                }
            }
            _ => {
                if let Some((&first, rest)) = refs.split_first() {
                    for w in rest.windows(2) {
                        push_unless_repeated(&mut push, [w[0], w[1], first]);
                    }
                }
            }
        }
        positions.extend_from_slice(&points);
    }
    if triangles.is_empty() {
        return Err(LoadError::NoTriangles { format });
    }
    Ok(Mesh::new(positions, triangles))
}

/// A primitive's positions placed by its node's transform; refuses one that is not finite,
/// before or after.
fn placed_points(job: &Job, data: &[u8], format: Format) -> Result<Vec<[f32; 3]>, LoadError> {
    let mut points = read_vectors::<3>(&job.positions, data, format)?;
    if let Some(v) = points.iter().flatten().find(|v| !v.is_finite()) {
        return Err(LoadError::NonFinite {
            format,
            location: Location::Item("accessor", job.positions.accessor),
            value: v.to_string(),
        });
    }
    let m = &job.instance.matrix;
    // The identity is skipped so that untransformed positions keep their exact bits (-0.0).
    if *m != IDENTITY {
        for p in &mut points {
            *p = transform_point(m, *p);
        }
        if let Some(v) = points.iter().flatten().find(|v| !v.is_finite()) {
            return Err(LoadError::NonFinite {
                format,
                location: Location::Item("node", job.instance.node),
                value: format!("{v} after the node's transform"),
            });
        }
    }
    Ok(points)
}

/// A primitive's vertex references (its indices, else every vertex in order), each checked
/// against its `count` vertices, whole triangles for a triangle list.
fn vertex_refs<'b>(
    job: &Job,
    count: usize,
    data: &impl Fn(&Layout) -> Result<&'b [u8], LoadError>,
    format: Format,
) -> Result<Vec<u32>, LoadError> {
    let refs: Vec<u32> = match &job.indices {
        Some(l) => {
            let refs = read_indices(l, data(l)?, format)?;
            if let Some(&bad) = refs.iter().find(|&&i| i as usize >= count) {
                return Err(LoadError::IndexOutOfRange {
                    format,
                    location: Location::Item("accessor", l.accessor),
                    index: bad.into(),
                    count,
                });
            }
            refs
        }
        // Counts are capped far below u32::MAX.
        None => (0..count as u32).collect(),
    };
    if job.mode == Mode::Triangles && !refs.len().is_multiple_of(3) {
        let accessor = job.indices.as_ref().unwrap_or(&job.positions).accessor;
        return Err(LoadError::Syntax {
            format,
            location: Location::Item("accessor", accessor),
            detail: format!(
                "{} vertex references do not make whole triangles",
                refs.len()
            ),
        });
    }
    Ok(refs)
}

/// Strips and fans join runs with repeated indices; those are not triangles of the surface.
fn push_unless_repeated(push: &mut impl FnMut([u32; 3]), t: [u32; 3]) {
    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
        push(t);
    }
}

/// The triangle primitives of every instance, in order, with accessors checked.
fn plan<'a>(
    root: &Root,
    compression: &Compression,
    instances: &'a [Instance],
    format: Format,
) -> Result<Vec<Job<'a>>, LoadError> {
    let mut jobs = Vec::new();
    for instance in instances {
        let mesh = root
            .meshes
            .get(instance.mesh)
            .ok_or_else(|| LoadError::Syntax {
                format,
                location: Location::Item("node", instance.node),
                detail: format!("mesh {} does not exist", instance.mesh),
            })?;
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let bad = |detail: String| LoadError::Syntax {
                format,
                location: Location::Item("mesh", instance.mesh),
                detail: format!("primitive {p}: {detail}"),
            };
            let Checked::Valid(mode) = primitive.mode else {
                return Err(bad("invalid mode".into()));
            };
            if !triangle_mode(mode) {
                continue;
            }
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions))
                .ok_or_else(|| bad("has no POSITION attribute".into()))?;
            jobs.push(Job {
                instance,
                mode,
                positions: layout(root, compression, position.value(), format)?,
                indices: primitive
                    .indices
                    .map(|i| layout(root, compression, i.value(), format))
                    .transpose()?,
            });
        }
    }
    Ok(jobs)
}
