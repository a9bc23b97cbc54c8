// volray.view's widget (anywidget): the viewer's page in a sandboxed
// iframe (its document from the kernel, `_page`), its messages carried
// over the kernel's comm: the page's requests as {view, text}, the
// viewer's answers back as {view, text} or {view, frame} with the frame's
// bytes as the message's buffer. Each view of the widget (each output
// showing it) is a page of its own with its own renderer, named `view`.
// The page takes the notebook's colours (JupyterLab's and Notebook 7's
// --jp-* variables) and follows a change of theme.
//
// Each frame is acknowledged ({view, ack}) once handed to the page: the
// kernel sends the next only while few are unacknowledged. Every
// `_heartbeat_ms` the view says it is alive ({view, alive}): a reloaded
// or closed browser tab sends no close, and the kernel closes the
// renderer of a view it no longer hears from. A view the kernel closed
// while it was silent (a hidden tab's timers are throttled) is told so
// ({view, gone}) and opens again, keeping what the page shows.

const THEME = {
  "--bg": "--jp-layout-color2",
  "--panel": "--jp-layout-color1",
  "--line": "--jp-border-color1",
  "--text": "--jp-ui-font-color1",
  "--muted": "--jp-ui-font-color2",
  "--accent": "--jp-brand-color1",
  "--error": "--jp-error-color1",
};

function theme(el) {
  const style = getComputedStyle(el);
  const vars = {};
  for (const [ours, theirs] of Object.entries(THEME)) {
    const value = style.getPropertyValue(theirs).trim();
    if (value) vars[ours] = value;
  }
  const light = document.body.dataset.jpThemeLight;
  return { volray: "theme", vars, light: light === undefined ? null : light === "true" };
}

function render({ model, el }) {
  const view = `${Date.now().toString(36)}-${Math.random().toString(36).slice(2)}`;
  const iframe = document.createElement("iframe");
  // Scripts only: an opaque origin, no access to the notebook's page,
  // cookies or storage; downloads for "Save PNG".
  iframe.setAttribute("sandbox", "allow-scripts allow-downloads");
  iframe.setAttribute("allow", "fullscreen; clipboard-write");
  iframe.className = "volray-view";
  iframe.title = "volray view";
  iframe.style.width = "100%";
  iframe.style.height = `${model.get("height")}px`;
  iframe.style.border = "0";
  iframe.style.display = "block";
  el.appendChild(iframe);

  const toPage = (message, transfer) => {
    if (iframe.contentWindow) iframe.contentWindow.postMessage(message, "*", transfer || []);
  };
  let opened = false; // the page asked for its renderer
  const onPage = (event) => {
    if (event.source !== iframe.contentWindow || !event.data) return;
    const m = event.data;
    if (m.volray === "open") {
      toPage(theme(el));
      opened = true;
      model.send({ view, open: true });
    } else if (m.volray === "text" && typeof m.text === "string") {
      model.send({ view, text: m.text });
    }
  };
  window.addEventListener("message", onPage);
  const onKernel = (content, buffers) => {
    if (!content || content.view !== view) return;
    if (typeof content.text === "string") {
      toPage({ volray: "text", text: content.text });
    } else if (content.frame && buffers && buffers.length) {
      const b = buffers[0];
      const bytes = new Uint8Array(b.buffer, b.byteOffset, b.byteLength).slice();
      toPage({ volray: "frame", data: bytes.buffer }, [bytes.buffer]);
      model.send({ view, ack: true });
    } else if (content.gone && opened) {
      model.send({ view, open: true, resume: true });
    } else if (content.closed) {
      opened = false;
      toPage({ volray: "closed" });
    }
  };
  model.on("msg:custom", onKernel);
  const onHeight = () => { iframe.style.height = `${model.get("height")}px`; };
  model.on("change:height", onHeight);
  // A change of the notebook's theme.
  const observer = new MutationObserver(() => toPage(theme(el)));
  observer.observe(document.body, { attributes: true, attributeFilter: ["data-jp-theme-name", "data-jp-theme-light"] });
  iframe.srcdoc = model.get("_page");
  const heartbeat = setInterval(() => {
    if (opened) model.send({ view, alive: true });
  }, model.get("_heartbeat_ms") || 2000);

  return () => {
    clearInterval(heartbeat);
    observer.disconnect();
    window.removeEventListener("message", onPage);
    model.off("msg:custom", onKernel);
    model.off("change:height", onHeight);
    model.send({ view, close: true });
  };
}

export default { render };
