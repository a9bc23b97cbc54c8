//! What the XML readers share (OME-XML in TIFF, BigDataViewer's
//! SpimData): an element's name and attributes without namespace
//! prefixes, through `quick-xml`.

use quick_xml::events::BytesStart;

/// An element's name without its namespace prefix.
pub(crate) fn local(e: &BytesStart) -> String {
    e.local_name().as_ref().to_string()
}

/// The XML attributes of `e` as (local name, value) pairs.
pub(crate) fn attributes(e: &BytesStart) -> Result<Vec<(String, String)>, String> {
    let mut out = Vec::new();
    for attr in e.attributes() {
        let attr = attr.map_err(|err| format!("bad XML attribute: {err}"))?;
        let key = attr.key.local_name().as_ref().to_string();
        let value = attr
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map_err(|err| format!("bad XML attribute {key}: {err}"))?
            .into_owned();
        out.push((key, value));
    }
    Ok(out)
}
