//! The GPU engine in a browser (`cargo test --target wasm32-unknown-unknown`, WebGPU from the
//! flags in webdriver.json): the path the web app takes. A run with the drifting reference, then the
//! readback of positions and references and the measure pass's readback, both polled between
//! turns of the event loop (nothing blocks), against the CPU engine in the same page. Every
//! kernel must also pass the browser's own WGSL compiler (Tint), which is stricter than naga in
//! places: no validation error may occur.
//!
//! Without WebGPU in the browser this test fails: CI's browser has it.
#![cfg(target_arch = "wasm32")]

use meshsmooth::gpu::{GpuSmoother, ResultReadback};
use meshsmooth::mesh::Topology;
use meshsmooth::metrics::{measure_vertices, DriftingReference, Original};
use meshsmooth::smooth::{smooth, Filter, Params};
use wasm_bindgen_test::{wasm_bindgen_test, wasm_bindgen_test_configure};

wasm_bindgen_test_configure!(run_in_browser);

const TUBE_PLY: &[u8] = include_bytes!("../../shared/data/synthetic/synthetic_bent_tube_r3.5.ply");

/// A WebGPU device with WebGPU's default limits, as eframe requests it.
async fn device() -> (wgpu::Device, wgpu::Queue) {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::BROWSER_WEBGPU,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapter = instance
        .request_adapter(&wgpu::RequestAdapterOptions::default())
        .await
        .expect("a WebGPU adapter (is --enable-unsafe-webgpu in webdriver.json?)");
    adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("meshsmooth browser test"),
            required_limits: wgpu::Limits::default(),
            ..Default::default()
        })
        .await
        .expect("a WebGPU device")
}

/// Lets the browser's event loop turn once (a zero-delay timeout): mappings complete there.
async fn next_turn() {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        web_sys::window()
            .expect("a window")
            .set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, 0)
            .expect("setTimeout");
    });
    wasm_bindgen_futures::JsFuture::from(promise)
        .await
        .expect("resolves");
}

/// Polls `try_take` once per turn of the event loop until it yields.
async fn poll<T>(mut try_take: impl FnMut() -> Option<T>) -> T {
    for _ in 0..10_000 {
        if let Some(value) = try_take() {
            return value;
        }
        next_turn().await;
    }
    panic!("the mapping never completed");
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

#[wasm_bindgen_test]
async fn drift_readback_and_measures_run_in_the_browser() {
    let mesh = meshsmooth::io::load(TUBE_PLY, "tube.ply").expect("parses");
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);
    let (device, queue) = device().await;
    // The browser reports invalid pipelines and dispatches asynchronously: catch them all.
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let smoother = GpuSmoother::new(&device);
    let mut uploaded = smoother
        .upload_with_measures(&device, &original)
        .expect("fits");
    let params = Params {
        iterations: 30,
        ..Params::defaults(Filter::Laplace)
    };
    smoother
        .smooth(&device, &queue, &mut uploaded, &params)
        .expect("valid");
    let pending = ResultReadback::start(&device, &queue, &uploaded).expect("has measures");
    let result = poll(|| pending.try_take()).await.expect("mapped");

    // The CPU engine in the same page.
    let mut drift = DriftingReference::new(&original);
    let cpu = smooth(&mesh, &topology, &params, None, &mut drift);
    let worst = result
        .positions
        .iter()
        .zip(&cpu)
        .map(|(a, b)| (0..3).map(|k| f64::from(a[k] - b[k]).powi(2)).sum::<f64>())
        .fold(0.0, f64::max)
        .sqrt();
    assert!(worst <= 1e-4 * mesh.bounding_box_diagonal(), "{worst}");
    let differing = (result.reference.iter())
        .zip(drift.reference())
        .filter(|(a, b)| a != b)
        .count();
    let drifted = (0..cpu.len())
        .filter(|&i| drift.reference()[i] != i as u32)
        .count();
    assert!(drifted > 100, "{drifted} references drifted");
    assert!(
        differing * 200 <= cpu.len(),
        "{differing} references differ"
    );

    // Normals too, so the browser's compiler sees every kernel before the error scope closes.
    smoother
        .compute_normals(&device, &queue, &uploaded)
        .expect("has measures");
    let pending = smoother
        .measure(&device, &queue, &uploaded, true)
        .expect("has measures");
    let on_gpu = poll(|| pending.try_take(&original, 0.5))
        .await
        .expect("mapped");
    if let Some(e) = scope.pop().await {
        panic!("WebGPU validation error: {e}");
    }
    let (metrics, vertex) = measure_vertices(&original, &result.positions, &result.reference, 0.5);
    let volume = relative(
        on_gpu.metrics.volume.expect("closed"),
        metrics.volume.expect("closed"),
    );
    assert!(volume <= 1e-6, "volume {volume}");
    assert!(relative(on_gpu.metrics.mean_error, metrics.mean_error) <= 1e-5);
    assert!(relative(on_gpu.metrics.curvature, metrics.curvature) <= 1e-4);
    wasm_bindgen_test::console_log!(
        "browser: positions within {:.1e} of the diagonal, {differing} of {} references differ ({drifted} drifted); relative V {volume:.1e}, E {:.1e}, K {:.1e}",
        worst / mesh.bounding_box_diagonal(),
        cpu.len(),
        relative(on_gpu.metrics.mean_error, metrics.mean_error),
        relative(on_gpu.metrics.curvature, metrics.curvature),
    );
    let gpu_vertex = on_gpu.vertex.expect("asked for");
    assert_eq!(gpu_vertex.local_error.len(), vertex.local_error.len());
}
