//! The tokens of an HTML page as the tests read them: html5gum (a WHATWG-conformant
//! tokenizer) with tag names, attributes and text decoded, and any parse error a failure.

use html5gum::{Token, Tokenizer};

/// A start tag.
pub struct Tag {
    /// The element's name.
    pub name: String,
    /// Its attributes (name, value), in order.
    pub attributes: Vec<(String, String)>,
    /// Whether it closes itself (`<br/>`).
    pub self_closing: bool,
}

/// One token of a page.
pub enum Html {
    /// A start tag.
    Start(Tag),
    /// An end tag's name.
    End(String),
    /// Text between tags.
    Text(String),
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).to_string()
}

/// The tokens of `html` in order (comments and the doctype left out); panics on a parse
/// error.
pub fn tokens(html: &str) -> Vec<Html> {
    let mut out = Vec::new();
    for token in Tokenizer::new(html) {
        let Ok(token) = token;
        match token {
            Token::Error(e) => panic!("HTML parse error: {e:?}"),
            Token::StartTag(tag) => out.push(Html::Start(Tag {
                name: text(&tag.name),
                attributes: tag
                    .attributes
                    .iter()
                    .map(|(k, v)| (text(k), text(v)))
                    .collect(),
                self_closing: tag.self_closing,
            })),
            Token::EndTag(tag) => out.push(Html::End(text(&tag.name))),
            Token::String(s) => out.push(Html::Text(text(&s))),
            _ => {}
        }
    }
    out
}
