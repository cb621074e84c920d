//! The page's engine workers: dedicated module workers (`web/worker.js`), each running this
//! very wasm, which answer the CPU engine's requests ([`crate::worker`]) in messages with
//! transferred buffers. No SharedArrayBuffer, so no cross-origin isolation is needed and the
//! page works inside any iframe. Replies land in an inbox the frame drains, and wake egui.

use std::cell::RefCell;
use std::rc::Rc;

use eframe::egui;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

use crate::worker::{decode, encode, Carrier, Reply, Request};

type Inbox = Rc<RefCell<Vec<(usize, Reply)>>>;

/// What runs as a reply lands, between frames.
type OnReply = Rc<RefCell<Option<Box<dyn FnMut() -> bool>>>>;

/// The workers, with the message handlers that must live as long as they do.
pub struct WebWorkers {
    workers: Vec<web_sys::Worker>,
    inbox: Inbox,
    on_reply: OnReply,
    handlers: Vec<Closure<dyn FnMut(web_sys::MessageEvent)>>,
    /// What a worker is started with (the glue's URL and the compiled module), kept to
    /// restart one.
    start: js_sys::Object,
    ctx: egui::Context,
}

/// How many workers do the background's work (guidance, "Suggest all"): one per core, leaving
/// one to the page and one to the view worker, at least one; the page's `?workers=N` overrides
/// it (benchmarks compare pool sizes). The view worker comes on top: it runs while the author
/// waits for a result, and takes structures of "Suggest all" meanwhile (restarted should the
/// view need it), so on two cores "Suggest all" has both.
pub fn pool_size() -> usize {
    let asked = super::query::param("workers").and_then(|n| n.parse::<usize>().ok());
    let cores = web_sys::window().map_or(1.0, |w| w.navigator().hardware_concurrency());
    asked
        .unwrap_or((cores as usize).saturating_sub(2))
        .clamp(1, 16)
}

impl WebWorkers {
    /// Runs `hook` whenever a reply lands, between frames: the pool hands the worker its next
    /// job there, instead of leaving it idle until the next frame (which can take long while a
    /// large mesh is drawn). The hook says whether what the page shows changed, so that a
    /// frame is due at once.
    pub fn on_reply(&self, hook: Box<dyn FnMut() -> bool>) {
        *self.on_reply.borrow_mut() = Some(hook);
    }

    /// Starts `count` workers on the page's own wasm, waking `ctx` when a reply comes.
    pub fn start(count: usize, ctx: &egui::Context) -> Result<Self, String> {
        let glue = own_glue_url()?;
        // The page's compiled module itself: no worker downloads or compiles it again.
        let wasm = wasm_bindgen::module();
        let inbox: Inbox = Rc::default();
        let on_reply: OnReply = Rc::default();
        let start = js_sys::Object::new();
        let set = |k: &str, v: &JsValue| js_sys::Reflect::set(&start, &k.into(), v);
        set("glue", &glue.as_str().into())
            .and_then(|_| set("wasm", &wasm))
            .ok();
        let mut pool = Self {
            workers: Vec::new(),
            inbox,
            on_reply,
            handlers: Vec::new(),
            start,
            ctx: ctx.clone(),
        };
        let mut first = started_by_page();
        for index in 0..count.max(1) {
            let worker = match first.take() {
                Some(worker) => worker,
                None => new_worker(index)?,
            };
            let handler = pool.begin(index, &worker)?;
            pool.workers.push(worker);
            pool.handlers.push(handler);
        }
        Ok(pool)
    }

    /// Hands `worker` (number `index`) its start message and returns its replies' handler.
    fn begin(
        &self,
        index: usize,
        worker: &web_sys::Worker,
    ) -> Result<Closure<dyn FnMut(web_sys::MessageEvent)>, String> {
        let (inbox, on_reply) = (self.inbox.clone(), self.on_reply.clone());
        let handler = reply_handler(index, inbox, on_reply, self.ctx.clone());
        worker.set_onmessage(Some(handler.as_ref().unchecked_ref()));
        worker
            .post_message(&self.start)
            .map_err(|e| format!("cannot start a worker: {}", super::page::js_error_text(&e)))?;
        Ok(handler)
    }
}

/// The first worker, if index.html started it (`window.meshsmoothWorker`); taken once.
fn started_by_page() -> Option<web_sys::Worker> {
    super::page::take_from_window("meshsmoothWorker")?
        .dyn_into::<web_sys::Worker>()
        .ok()
}

fn new_worker(index: usize) -> Result<web_sys::Worker, String> {
    let options = web_sys::WorkerOptions::new();
    options.set_type(web_sys::WorkerType::Module);
    options.set_name(&format!("meshsmooth engine {}", index + 1));
    web_sys::Worker::new_with_options("worker.js", &options)
        .map_err(|e| format!("cannot start a worker: {}", super::page::js_error_text(&e)))
}

/// The handler of worker `index`'s messages: a reply's bytes, or why the worker failed.
fn reply_handler(
    index: usize,
    inbox: Inbox,
    on_reply: OnReply,
    ctx: egui::Context,
) -> Closure<dyn FnMut(web_sys::MessageEvent)> {
    Closure::new(move |event: web_sys::MessageEvent| {
        let data = event.data();
        // Progress, the runs of background work (graphs, searches) and the structures of
        // "Suggest all" (taken between frames) only move a bar on and change surfaces a second
        // later: a frame for each would take a core from the workers with a software GPU.
        let mut paced = false;
        if let Some(buffer) = data.dyn_ref::<js_sys::ArrayBuffer>() {
            let bytes = js_sys::Uint8Array::new(buffer).to_vec();
            match decode::<Reply>(&bytes) {
                Ok(reply) => {
                    paced = matches!(
                        reply,
                        Reply::Progress { .. }
                            | Reply::Terms { .. }
                            | Reply::Memory { .. }
                            | Reply::Suggested { .. }
                    );
                    inbox.borrow_mut().push((index, reply))
                }
                Err(why) => {
                    // The worker's job cannot be answered: it fails instead of waiting forever.
                    log::error!("engine worker {}: {why}", index + 1);
                    inbox.borrow_mut().push((index, Reply::Broken { why }));
                }
            }
        } else {
            let why = js_sys::JSON::stringify(&data).map_or_else(|_| "?".into(), String::from);
            log::error!("engine worker {} failed: {why}", index + 1);
            let why = format!("engine worker {} failed: {why}", index + 1);
            inbox.borrow_mut().push((index, Reply::Broken { why }));
        }
        let mut shown_changed = false;
        if let Ok(mut hook) = on_reply.try_borrow_mut() {
            if let Some(hook) = hook.as_mut() {
                shown_changed = hook();
            }
        }
        if paced && !shown_changed {
            ctx.request_repaint_after(super::Pacing::of(&ctx).work_repaint);
        } else {
            super::wake(&ctx);
        }
    })
}

/// The URL of the page's wasm-bindgen glue, as the build linked it (a hashed name).
fn own_glue_url() -> Result<String, String> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    document
        .query_selector("link[rel=modulepreload][href$='.js']")
        .ok()
        .flatten()
        .and_then(|e| e.get_attribute("href"))
        .and_then(|h| web_sys::Url::new_with_base(&h, &document.base_uri().ok()??).ok())
        .map(|u| u.href())
        .ok_or_else(|| "the page does not name its wasm module's glue".to_string())
}

impl Carrier for WebWorkers {
    fn workers(&self) -> usize {
        self.workers.len()
    }

    fn post(&mut self, worker: usize, request: &Request) {
        let bytes = js_sys::Uint8Array::from(encode(request).as_slice());
        let buffer = bytes.buffer();
        let transfer = js_sys::Array::of1(&buffer);
        if let Err(e) = self.workers[worker].post_message_with_transfer(&buffer, &transfer) {
            log::error!(
                "engine worker {}: {}",
                worker + 1,
                super::page::js_error_text(&e)
            );
        }
    }

    fn take_replies(&mut self) -> Vec<(usize, Reply)> {
        std::mem::take(&mut self.inbox.borrow_mut())
    }

    fn threaded(&self) -> bool {
        true
    }

    fn restartable(&self) -> bool {
        true
    }

    fn restart(&mut self, worker: usize) -> bool {
        let fresh = match new_worker(worker) {
            Ok(fresh) => fresh,
            Err(why) => {
                log::error!("{why}");
                return false;
            }
        };
        let handler = match self.begin(worker, &fresh) {
            Ok(handler) => handler,
            Err(why) => {
                log::error!("{why}");
                fresh.terminate();
                return false;
            }
        };
        // The old one's replies, come or still to come, are its job's: none is delivered.
        let old = std::mem::replace(&mut self.workers[worker], fresh);
        old.set_onmessage(None);
        old.terminate();
        self.inbox.borrow_mut().retain(|(w, _)| *w != worker);
        self.handlers[worker] = handler;
        true
    }
}

thread_local! {
    /// The engine state of this worker (in a worker's wasm instance).
    static ENGINE: RefCell<crate::worker::Worker> = RefCell::default();
}

/// Called by `web/worker.js` with each request's bytes: the reply's bytes, if any. `tell`
/// posts the replies sent before it (an opening's stages), each as its bytes.
#[wasm_bindgen]
pub fn worker_handle(request: &[u8], tell: &js_sys::Function) -> Option<Vec<u8>> {
    let mut post = |reply: Reply| {
        let bytes = js_sys::Uint8Array::from(encode(&reply).as_slice());
        if let Err(e) = tell.call1(&JsValue::NULL, &bytes) {
            log::error!("{}", super::page::js_error_text(&e));
        }
    };
    let reply = match decode::<Request>(request) {
        Ok(request) => ENGINE.with(|e| {
            e.borrow_mut()
                .handle(request, &crate::worker::clock_ms, &mut post)
        }),
        Err(why) => {
            log::error!("{why}");
            Some(Reply::Broken { why })
        }
    };
    post(Reply::Memory {
        bytes: memory_bytes(),
    });
    reply.map(|r| encode(&r))
}

/// The bytes of this wasm instance's memory (the page's, or a worker's).
pub fn memory_bytes() -> u64 {
    wasm_bindgen::memory()
        .dyn_into::<js_sys::WebAssembly::Memory>()
        .map_or(0, |m| {
            m.buffer()
                .dyn_into::<js_sys::ArrayBuffer>()
                .map_or(0, |b| u64::from(b.byte_length()))
        })
}
