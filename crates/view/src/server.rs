//! The HTTP server: the page and its assets, the WebSocket of each tab,
//! and `/api/status`, every one behind the access token (403 without it).
//!
//! No route takes a path or a file name: the only files the viewer reads
//! are the ones its caller read before starting it. The server binds
//! before it runs, so that the caller can print the URL first; it stops
//! when its [`Stopper`] is called, closing every tab's renderer.

use crate::ledger::Reservation;
use crate::link::Host;
use crate::mailbox::Mailbox;
use crate::page;
use crate::protocol::{MAX_MESSAGE_BYTES, Request, ServerMessage, file};
use crate::session::{self, Outgoing, Shared};
use crate::token::Token;
use axum::Router;
use axum::body::Body;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Request as HttpRequest, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use std::net::{SocketAddr, TcpListener};
use std::sync::{Arc, Mutex, Weak};
use tokio::sync::{Notify, mpsc};

/// The server could not start or run.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        addr: SocketAddr,
        source: std::io::Error,
    },
    #[error("cannot start the server's threads: {0}")]
    Runtime(std::io::Error),
    #[error("the server failed: {0}")]
    Serve(std::io::Error),
}

/// What the routes share.
struct App {
    token: Token,
    /// The page's first message, the same for every tab.
    hello: String,
    shared: Shared,
    /// Every tab's mailbox, to close them when the server stops.
    mailboxes: Mutex<Vec<Weak<Mailbox<Request>>>>,
    /// The volume's bytes in the ledger, for as long as the server lives.
    _volume: Reservation,
}

/// A bound server, not yet serving.
pub struct Server {
    listener: TcpListener,
    app: Arc<App>,
    stop: Arc<Notify>,
}

/// Stops a running server from another thread (a signal handler's).
#[derive(Clone)]
pub struct Stopper(Arc<Notify>);

impl Stopper {
    /// Asks the server to stop; [`Server::run`] then returns.
    pub fn stop(&self) {
        self.0.notify_one();
    }
}

impl Server {
    /// Binds `addr` (port 0: any free port).
    pub fn bind(addr: SocketAddr, token: Token, host: Host) -> Result<Server, ServeError> {
        let Host {
            hello,
            shared,
            volume,
        } = host;
        let bind_error = |source| ServeError::Bind { addr, source };
        let listener = TcpListener::bind(addr).map_err(bind_error)?;
        listener.set_nonblocking(true).map_err(bind_error)?;
        Ok(Server {
            listener,
            app: Arc::new(App {
                token,
                hello,
                shared,
                mailboxes: Mutex::new(Vec::new()),
                _volume: volume,
            }),
            stop: Arc::new(Notify::new()),
        })
    }

    /// The address the server listens on.
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// The page's URL, token included: the host is the bound address, or
    /// the loopback address of its family when bound to every interface.
    pub fn url(&self) -> std::io::Result<String> {
        let addr = self.local_addr()?;
        let host = match addr.ip() {
            std::net::IpAddr::V4(ip) if ip.is_unspecified() => "127.0.0.1".to_string(),
            std::net::IpAddr::V6(ip) if ip.is_unspecified() => "[::1]".to_string(),
            std::net::IpAddr::V4(ip) => ip.to_string(),
            std::net::IpAddr::V6(ip) => format!("[{ip}]"),
        };
        Ok(format!(
            "http://{host}:{}/?token={}",
            addr.port(),
            self.app.token.as_str()
        ))
    }

    /// A handle that stops the server.
    pub fn stopper(&self) -> Stopper {
        Stopper(Arc::clone(&self.stop))
    }

    /// Serves until stopped, then closes every tab.
    pub fn run(self) -> Result<(), ServeError> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("view-http")
            .enable_all()
            .build()
            .map_err(ServeError::Runtime)?;
        let Server {
            listener,
            app,
            stop,
        } = self;
        let router = router(Arc::clone(&app));
        let served = runtime.block_on(async move {
            let listener = tokio::net::TcpListener::from_std(listener)?;
            axum::serve(listener, router)
                .with_graceful_shutdown(async move { stop.notified().await })
                .await
        });
        for mailbox in app
            .mailboxes
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
        {
            if let Some(mailbox) = mailbox.upgrade() {
                mailbox.close();
            }
        }
        // Open sockets end with the runtime.
        runtime.shutdown_background();
        served.map_err(ServeError::Serve)
    }
}

fn router(app: Arc<App>) -> Router {
    Router::new()
        .route("/", get(index))
        .route(
            "/app.js",
            get(|| async { asset(page::APP_JS, "text/javascript") }),
        )
        .route(
            "/style.css",
            get(|| async { asset(page::STYLE_CSS, "text/css") }),
        )
        .route("/ws", get(socket))
        .route("/api/status", get(status))
        .fallback(|| async { (StatusCode::NOT_FOUND, "not found") })
        .layer(middleware::from_fn_with_state(Arc::clone(&app), guard))
        .with_state(app)
}

/// Refuses every request without the token, and sets the headers every
/// answer carries: nothing cached, no referrer (the URL holds the token),
/// only the page's own scripts.
async fn guard(State(app): State<Arc<App>>, request: HttpRequest, next: Next) -> Response {
    let mut response = if app.token.in_query(request.uri().query()) {
        next.run(request).await
    } else {
        (
            StatusCode::FORBIDDEN,
            "403 forbidden: this URL needs the access token volray view printed\n",
        )
            .into_response()
    };
    let headers = response.headers_mut();
    for (name, value) in [
        (header::CACHE_CONTROL, "no-store"),
        (header::REFERRER_POLICY, "no-referrer"),
        (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
        (
            header::CONTENT_SECURITY_POLICY,
            "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob:; connect-src 'self' blob:; base-uri 'none'; form-action 'none'; frame-ancestors 'none'",
        ),
    ] {
        headers.insert(name, HeaderValue::from_static(value));
    }
    response
}

/// The page, with the token in the URLs of its assets.
async fn index(State(app): State<Arc<App>>) -> Response {
    asset(
        page::index_html(app.token.as_str()),
        "text/html; charset=utf-8",
    )
}

fn asset(body: impl Into<Body>, mime: &'static str) -> Response {
    ([(header::CONTENT_TYPE, mime)], body.into()).into_response()
}

async fn status(State(app): State<Arc<App>>) -> Response {
    let snapshot = app.shared.stats.snapshot(&app.shared.ledger);
    let json = serde_json::to_string(&snapshot).expect("counters serialise");
    asset(json, "application/json")
}

/// A tab's WebSocket. A request from another site's page (its `Origin`
/// is not this server) is refused even with the token.
async fn socket(
    State(app): State<Arc<App>>,
    headers: HeaderMap,
    upgrade: WebSocketUpgrade,
) -> Response {
    if !same_origin(&headers) {
        return (
            StatusCode::FORBIDDEN,
            "403 forbidden: cross-origin WebSocket",
        )
            .into_response();
    }
    upgrade
        .max_message_size(MAX_MESSAGE_BYTES)
        .max_frame_size(MAX_MESSAGE_BYTES)
        .on_upgrade(move |socket| serve_tab(app, socket))
}

/// Whether the request's `Origin`, when it has one, is `http://` + its
/// `Host`.
fn same_origin(headers: &HeaderMap) -> bool {
    let Some(origin) = headers.get(header::ORIGIN) else {
        return true;
    };
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    match (origin.to_str().ok(), host) {
        (Some(origin), Some(host)) => origin.strip_prefix("http://") == Some(host),
        _ => false,
    }
}

/// Serves one tab: its first message is the [`protocol::Hello`]; then
/// requests go to the tab's mailbox and frames come back from its
/// renderer, until either side goes away.
async fn serve_tab(app: Arc<App>, mut socket: WebSocket) {
    let mailbox = Arc::new(Mailbox::default());
    let (out_tx, mut out_rx) = mpsc::channel::<Outgoing>(1);
    if let Err(e) = session::spawn(&app.shared, Arc::clone(&mailbox), out_tx) {
        let error = ServerMessage::Error {
            seq: None,
            message: e.to_string(),
        };
        let _ = socket.send(Message::Text(error.to_json().into())).await;
        return;
    }
    {
        let mut mailboxes = app.mailboxes.lock().unwrap_or_else(|e| e.into_inner());
        mailboxes.retain(|m| m.strong_count() > 0);
        mailboxes.push(Arc::downgrade(&mailbox));
    }
    if socket
        .send(Message::Text(app.hello.clone().into()))
        .await
        .is_ok()
    {
        loop {
            tokio::select! {
                incoming = socket.recv() => {
                    let reply = match incoming {
                        Some(Ok(Message::Text(text))) => receive(&mailbox, text.as_str()),
                        Some(Ok(Message::Binary(_))) => Some(ServerMessage::Error {
                            seq: None,
                            message: "binary messages are not understood: send JSON text".into(),
                        }),
                        Some(Ok(Message::Ping(_) | Message::Pong(_))) => None,
                        Some(Ok(Message::Close(_)) | Err(_)) | None => break,
                    };
                    if let Some(reply) = reply
                        && socket.send(Message::Text(reply.to_json().into())).await.is_err()
                    {
                        break;
                    }
                }
                outgoing = out_rx.recv() => {
                    // A frame's bytes stay reserved until it is sent.
                    let (message, _reserved) = match outgoing {
                        Some(Outgoing::Frame(bytes, reserved)) => {
                            (Message::Binary(bytes.into()), Some(reserved))
                        }
                        Some(Outgoing::Text(text)) => (Message::Text(text.into()), None),
                        None => break,
                    };
                    if socket.send(message).await.is_err() {
                        break;
                    }
                }
            }
        }
    }
    // Stops the frame being rendered, if any, and ends the tab's thread.
    mailbox.close();
}

/// Files a request from the page, or says why it was refused.
fn receive(mailbox: &Mailbox<Request>, text: &str) -> Option<ServerMessage> {
    file(mailbox, text).err()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(header::HeaderName, &str)]) -> HeaderMap {
        let mut map = HeaderMap::new();
        for (name, value) in pairs {
            map.insert(name.clone(), HeaderValue::from_str(value).unwrap());
        }
        map
    }

    #[test]
    fn only_this_servers_pages_open_sockets() {
        assert!(same_origin(&headers(&[(header::HOST, "127.0.0.1:8080")])));
        assert!(same_origin(&headers(&[
            (header::HOST, "localhost:8080"),
            (header::ORIGIN, "http://localhost:8080")
        ])));
        assert!(!same_origin(&headers(&[
            (header::HOST, "127.0.0.1:8080"),
            (header::ORIGIN, "http://evil.example")
        ])));
        assert!(!same_origin(&headers(&[(
            header::ORIGIN,
            "http://127.0.0.1:8080"
        )])));
    }

    #[test]
    fn requests_go_to_the_mailbox_and_bad_ones_are_answered() {
        let mailbox = Mailbox::default();
        let state = crate::state::ViewState::default();
        let good =
            serde_json::json!({"type": "view", "seq": 1, "quality": "draft", "state": state});
        assert!(receive(&mailbox, &good.to_string()).is_none());
        let save = serde_json::json!({"type": "save", "seq": 2, "state": state});
        assert!(receive(&mailbox, &save.to_string()).is_none());
        assert_eq!(mailbox.waiting(), 2);
        let bad =
            serde_json::json!({"type": "view", "seq": 3, "quality": "draft", "state": {"zoom": 1}});
        match receive(&mailbox, &bad.to_string()) {
            Some(ServerMessage::Error { seq, message }) => {
                assert_eq!(seq, Some(3));
                assert!(message.starts_with("malformed message"), "{message}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(mailbox.take().map(|r| r.seq), Some(2));
        assert_eq!(mailbox.take().map(|r| r.seq), Some(1));
    }
}
