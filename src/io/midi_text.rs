//! Text as a Standard MIDI File's meta events carry it (the track names). The SMF
//! specification leaves their encoding open, and readers take the bytes as ASCII or
//! Latin-1 (ISO 8859-1; mido decodes them as Latin-1): UTF-8 bytes show as mojibake
//! there ("Pauken â\u{80}\u{93}"). So a text every character of which has a printable
//! Latin-1 code is written in Latin-1, one byte each ("Ouvertüre"); any other is
//! transliterated to ASCII as a whole ("Pauken – Tympani ♯" → "Pauken - Tympani #"):
//! accented Latin letters lose their accents, typographic dashes, quotes and spaces
//! become their ASCII kin, ♯ ♭ ♮ become `#`, `b`, `nat`, and what has no ASCII form `?`.
//! timpanist's MIDI import reads both back ([`super::midi_import::decode_text`]).

/// `text` as the bytes of a MIDI meta event: Latin-1 if it all fits, else ASCII.
pub fn encode(text: &str) -> Vec<u8> {
    match latin1(text) {
        Some(bytes) => bytes,
        None => ascii(text).into_bytes(),
    }
}

/// `text` in Latin-1, if every character is a printable Latin-1 one (no control codes).
fn latin1(text: &str) -> Option<Vec<u8>> {
    text.chars()
        .map(|c| match u32::from(c) {
            code @ (0x20..=0x7e | 0xa0..=0xff) => u8::try_from(code).ok(),
            _ => None,
        })
        .collect()
}

/// `text` transliterated to printable ASCII, character by character ([`ascii_of`]).
fn ascii(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match ascii_of(c) {
            Ascii::Same => out.push(c),
            Ascii::Letter(l) => out.push(l),
            Ascii::Text(t) => out.push_str(t),
        }
    }
    out
}

/// The ASCII for one character.
enum Ascii {
    /// The character itself (printable ASCII).
    Same,
    Letter(char),
    Text(&'static str),
}

/// Base letters of U+00C0–U+00FF (Latin-1's letters, × and ÷); `*` marks the ones
/// spelt with two letters ([`two_letters`]).
const LATIN1_LETTERS: &str = "AAAAAA*CEEEEIIIIDNOOOOOxOUUUUY**aaaaaa*ceeeeiiiidnooooo/ouuuuy*y";
/// Base letters of U+0100–U+017F (Latin Extended-A); `*` as above.
const EXTENDED_A_LETTERS: &str = "AaAaAaCcCcCcCcDdDdEeEeEeEeEeGgGgGgGgHhHhIiIiIiIiIi**JjKkkLlLlLlLlLlNnNnNn*NnOoOoOo**RrRrRrSsSsSsSsTtTtTtUuUuUuUuUuUuWwYyYZzZzZzs";

/// The ASCII for `c`: itself if printable ASCII, else its transliteration, else `?`.
fn ascii_of(c: char) -> Ascii {
    let code = u32::from(c);
    let letter_in = |table: &str, first: u32| match table.as_bytes()[(code - first) as usize] {
        b'*' => two_letters(c).map_or(Ascii::Letter('?'), Ascii::Text),
        l => Ascii::Letter(char::from(l)),
    };
    match code {
        0x20..=0x7e => Ascii::Same,
        0xc0..=0xff => letter_in(LATIN1_LETTERS, 0xc0),
        0x100..=0x17f => letter_in(EXTENDED_A_LETTERS, 0x100),
        _ => symbol(c).unwrap_or(Ascii::Letter('?')),
    }
}

/// The letters spelt with two in ASCII.
fn two_letters(c: char) -> Option<&'static str> {
    Some(match c {
        'Æ' => "AE",
        'æ' => "ae",
        'Þ' => "Th",
        'þ' => "th",
        'ß' => "ss",
        'Ĳ' => "IJ",
        'ĳ' => "ij",
        'ŉ' => "'n",
        'Œ' => "OE",
        'œ' => "oe",
        _ => return None,
    })
}

/// Spaces, punctuation and music signs that have an ASCII form.
fn symbol(c: char) -> Option<Ascii> {
    Some(match c {
        c if c.is_whitespace() || c.is_control() => Ascii::Letter(' '),
        '\u{ad}' | '\u{200b}'..='\u{200d}' | '\u{2060}' | '\u{feff}' => Ascii::Text(""),
        '‐'..='―' | '−' | '¬' | '¯' => Ascii::Letter('-'),
        '‘' | '’' | '‚' | '‛' | '′' | '´' => Ascii::Letter('\''),
        '“' | '”' | '„' | '‟' | '″' | '«' | '»' | '¨' => Ascii::Letter('"'),
        '‹' => Ascii::Letter('<'),
        '›' => Ascii::Letter('>'),
        '…' => Ascii::Text("..."),
        '•' | '·' => Ascii::Letter('.'),
        '¡' => Ascii::Letter('!'),
        '¿' => Ascii::Letter('?'),
        '¦' => Ascii::Letter('|'),
        '§' => Ascii::Text("S"),
        '©' => Ascii::Text("(c)"),
        '®' => Ascii::Text("(R)"),
        '°' => Ascii::Text(" deg"),
        '±' => Ascii::Text("+/-"),
        '¹' => Ascii::Letter('1'),
        '²' => Ascii::Letter('2'),
        '³' => Ascii::Letter('3'),
        'ª' => Ascii::Letter('a'),
        'º' => Ascii::Letter('o'),
        'µ' => Ascii::Letter('u'),
        '¼' => Ascii::Text("1/4"),
        '½' => Ascii::Text("1/2"),
        '¾' => Ascii::Text("3/4"),
        '¢' => Ascii::Letter('c'),
        '£' => Ascii::Text("GBP"),
        '¥' => Ascii::Text("JPY"),
        '€' => Ascii::Text("EUR"),
        '♯' => Ascii::Letter('#'),
        '♭' => Ascii::Letter('b'),
        '♮' => Ascii::Text("nat"),
        '𝄪' => Ascii::Letter('x'),
        '𝄫' => Ascii::Text("bb"),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every letter of the two tables has its place.
    #[test]
    fn tables_cover_their_ranges() {
        assert_eq!(LATIN1_LETTERS.len(), 0x100 - 0xc0);
        assert_eq!(EXTENDED_A_LETTERS.len(), 0x180 - 0x100);
        for code in (0xc0..0x180).filter_map(char::from_u32) {
            assert!(!matches!(ascii_of(code), Ascii::Letter('?')), "{code}");
        }
    }

    /// Latin-1 text stays Latin-1, one byte a character; anything else becomes ASCII as a
    /// whole, accents and all.
    #[test]
    fn latin1_where_it_fits_else_ascii() {
        assert_eq!(encode("Timpani"), b"Timpani");
        assert_eq!(
            encode("Ouvertüre für Pauken"),
            b"Ouvert\xfcre f\xfcr Pauken"
        );
        assert_eq!(encode("Pauken – Tympani ♯"), b"Pauken - Tympani #");
        assert_eq!(encode("Pièce – B♭ “solo”…"), b"Piece - Bb \"solo\"...");
        assert_eq!(encode("Œuvre Dvořák Łódź"), b"OEuvre Dvorak Lodz");
        assert_eq!(encode("Straße\tnr. 2"), b"Strasse nr. 2");
        assert_eq!(encode("ティンパニ"), b"?????");
    }
}
