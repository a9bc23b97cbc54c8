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
}
