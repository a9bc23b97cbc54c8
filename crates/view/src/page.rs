//! The page, embedded in the binary: one HTML file, one script, one style
//! sheet, plain and without a build step, so that the viewer works
//! offline and over a tunnel with nothing fetched from anywhere else.
//! The HTML names its assets with the access token, which the server
//! writes into it.

/// The script: the frame, the controls, the WebSocket.
pub const APP_JS: &str = include_str!("../assets/app.js");

/// The style sheet.
pub const STYLE_CSS: &str = include_str!("../assets/style.css");

const INDEX_HTML: &str = include_str!("../assets/index.html");

/// The transport of the page in a notebook: a WebSocket whose messages
/// go through the parent window (`embedded_html`).
pub const EMBED_JS: &str = include_str!("../assets/embed.js");

/// What the page in a notebook may load: its own inline script and style
/// (by `nonce`) and its frames (blob URLs); nothing from the network.
fn embedded_csp(nonce: &str) -> String {
    format!(
        "default-src 'none'; script-src 'nonce-{nonce}'; style-src 'nonce-{nonce}'; img-src blob:; connect-src blob:; base-uri 'none'; form-action 'none'"
    )
}

/// The page as one document for an iframe's `srcdoc` (the Jupyter
/// widget's): the style sheet and the scripts inline, allowed by `nonce`
/// in a Content-Security-Policy `meta` element, `assets/embed.js` before the
/// page's script so that its messages go through the parent window.
pub fn embedded_html(nonce: &str) -> String {
    let head = format!(
        "<meta http-equiv=\"Content-Security-Policy\" content=\"{}\">\n<style nonce=\"{nonce}\">\n{STYLE_CSS}</style>",
        embedded_csp(nonce)
    );
    let scripts = format!(
        "<script nonce=\"{nonce}\">\n{EMBED_JS}</script>\n<script nonce=\"{nonce}\">\n{APP_JS}</script>\n</body>"
    );
    INDEX_HTML
        .replace(
            "<link rel=\"stylesheet\" href=\"style.css?token={{TOKEN}}\">",
            &head,
        )
        .replace(
            "<script src=\"app.js?token={{TOKEN}}\" defer></script>\n",
            "",
        )
        .replace("</body>", &scripts)
}

/// The HTML page, its asset URLs carrying `token`.
pub fn index_html(token: &str) -> String {
    INDEX_HTML.replace("{{TOKEN}}", token)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_names_its_assets_with_the_token_and_has_the_hooks() {
        let html = index_html("abc123");
        assert!(html.contains("app.js?token=abc123"));
        assert!(html.contains("style.css?token=abc123"));
        assert!(!html.contains("{{TOKEN}}"));
        assert!(html.contains(r#"id="frame""#));
        // Nothing from elsewhere: no absolute URLs in the page or script.
        for text in [INDEX_HTML, APP_JS, STYLE_CSS] {
            assert!(!text.contains("http://") && !text.contains("https://"));
        }
        assert!(APP_JS.contains("dataset.frames") && APP_JS.contains("\"still\""));
        assert!(APP_JS.contains("dataset.level") && APP_JS.contains("header.level"));
    }

    #[test]
    fn the_embedded_page_inlines_its_parts_under_its_csp() {
        let html = embedded_html("n0nce");
        assert!(!html.contains("{{TOKEN}}") && !html.contains("src=\"app.js"));
        assert!(!html.contains("href=\"style.css"));
        assert!(html.contains("script-src 'nonce-n0nce'"));
        assert_eq!(html.matches("<script nonce=\"n0nce\">").count(), 2);
        assert_eq!(html.matches("<script").count(), 2, "no other script");
        assert!(html.find(EMBED_JS).unwrap() < html.find(APP_JS).unwrap());
        assert!(html.find(APP_JS).unwrap() > html.find(r#"id="frame""#).unwrap());
        assert!(html.contains(STYLE_CSS));
        // Nothing in the parts ends their elements early.
        for part in [APP_JS, EMBED_JS, STYLE_CSS] {
            assert!(!part.contains("</script") && !part.contains("</style"));
        }
    }
}
