// An engine worker of the page: runs the page's own wasm module (the glue's URL and the compiled
// module come in the first message) and answers every later message, a request's bytes,
// with the reply's bytes.
// Requests are done one after another, in the order they came.
let engine = null;

// Replies sent before a request's answer (an opening's stages), as their bytes.
const tell = (bytes) => self.postMessage(bytes.buffer, [bytes.buffer]);

self.onmessage = (event) => {
    if (engine === null) {
        const { glue, wasm } = event.data;
        engine = import(glue).then(async (module) => {
            await module.default({ module_or_path: wasm });
            return module;
        });
        engine.catch((error) => self.postMessage({ failed: String(error) }));
        return;
    }
    const request = new Uint8Array(event.data);
    engine = engine.then((module) => {
        try {
            const reply = module.worker_handle(request, tell);
            if (reply !== undefined) {
                self.postMessage(reply.buffer, [reply.buffer]);
            }
        } catch (error) {
            self.postMessage({ failed: String(error) });
        }
        return module;
    });
};
