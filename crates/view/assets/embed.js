// volray view in a notebook: the page runs in a sandboxed iframe (its own
// document, so the page's hooks body[data-state], body[data-frames] and
// #frame are its own), and its messages travel through the parent window
// (the Jupyter widget) over the kernel's connection instead of a
// WebSocket. This script runs before app.js and gives it a WebSocket of
// that kind: the same messages, the same order.
//
// From the parent: {volray: "text", text}, {volray: "frame", data:
// ArrayBuffer}, {volray: "closed"}, {volray: "theme", vars, light}. To
// the parent: {volray: "open"} once, then {volray: "text", text} for each
// message the page sends.
"use strict";

(() => {
  const parentWindow = window.parent;
  const post = (message) => parentWindow.postMessage(message, "*");

  class ParentSocket {
    static CONNECTING = 0;
    static OPEN = 1;
    static CLOSING = 2;
    static CLOSED = 3;

    constructor() {
      this.readyState = ParentSocket.CONNECTING;
      this.binaryType = "arraybuffer";
      this.onmessage = null;
      this.onclose = null;
      window.addEventListener("message", (event) => {
        if (event.source !== parentWindow || !event.data || typeof event.data !== "object") return;
        const m = event.data;
        if (m.volray === "text" && typeof m.text === "string") {
          // The first message is the hello: the connection is open.
          if (this.readyState === ParentSocket.CONNECTING) this.readyState = ParentSocket.OPEN;
          if (this.onmessage) this.onmessage({ data: m.text });
        } else if (m.volray === "frame" && m.data instanceof ArrayBuffer) {
          if (this.onmessage) this.onmessage({ data: m.data });
        } else if (m.volray === "closed") {
          if (this.readyState === ParentSocket.CLOSED) return;
          this.readyState = ParentSocket.CLOSED;
          if (this.onclose) this.onclose({});
        }
      });
      post({ volray: "open" });
    }

    send(text) {
      if (this.readyState === ParentSocket.OPEN) post({ volray: "text", text: String(text) });
    }

    close() {
      this.readyState = ParentSocket.CLOSED;
    }
  }

  window.WebSocket = ParentSocket;
  window.volrayEmbedded = true;

  // The notebook's theme: its colours as the page's.
  window.addEventListener("message", (event) => {
    if (event.source !== parentWindow || !event.data || event.data.volray !== "theme") return;
    const root = document.documentElement;
    for (const [name, value] of Object.entries(event.data.vars || {})) {
      if (/^--[a-z-]+$/.test(name) && typeof value === "string" && value) {
        root.style.setProperty(name, value);
      }
    }
    root.style.colorScheme = event.data.light === false ? "dark" : "light";
    document.body.dataset.theme = event.data.light === false ? "dark" : "light";
  });
})();
